//! Triangle-mesh boundaries: the BVH's ray casts against an independent f64 brute force, the
//! 12-triangle cube against the box (bit for bit), watertightness at shared edges and vertices,
//! the closedness checks, and the analytic absorber: an albedo-0 medium inside an index-matched
//! sphere and torus transmits exactly `exp(-sigma_t * chord)`.

mod common;

use common::{TestRng, Z_MAX};
use glam::DVec3;
use volpt_core::mesh::build::{build, check_closed, BuildError, MeshBuffers};
use volpt_core::mesh::distance::resolution_for;
use volpt_core::mesh::primitives::{cuboid, sphere, torus, IndexedMesh};
use volpt_core::microfacet::Ggx;
use volpt_core::path::{sample_pixel, trace};
use volpt_core::shape::Shape;
use volpt_core::{
    Aabb, BoundaryShape, ConstantEnvironment, DeviceBoundary, Estimator, HenyeyGreenstein,
    HomogeneousMedium, LatLongEnvironment, LatLongRows, NullBoundary, PathCounters, PathSettings,
    PathState, PerspectiveCamera, Ray, Rng, RoughDielectric, SmoothDielectric, Spectrum, Vec2,
    Vec3, VolumeScene,
};

/// The mesh's buffers with a distance grid of 16 cells along the longest axis, so that the
/// tests' flights skip the ray cast where they cannot reach the surface.
fn built((vertices, triangles): &IndexedMesh) -> MeshBuffers {
    let buffers = build(vertices, triangles).expect("a closed mesh builds");
    let res = resolution_for(buffers.bounds, 16);
    buffers.with_distances(res)
}

fn unit_box() -> Aabb {
    Aabb::new(Vec3::new(-1.0, -0.75, -0.5), Vec3::new(1.0, 0.75, 0.5))
}

/// The torus of the tests: not convex, and a ray through its hole crosses it twice.
fn test_torus() -> IndexedMesh {
    torus([0.1, -0.05, 0.0], 0.7, 0.3, 48, 24)
}

fn test_sphere() -> IndexedMesh {
    sphere([0.05, 0.0, -0.1], 0.8, 24, 48)
}

/// `6 * volume` of the mesh: positive when its triangles face outwards.
fn six_volume((vertices, triangles): &IndexedMesh) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| Vec3::from(vertices[i as usize]).as_dvec3());
            a.dot(b.cross(c))
        })
        .sum()
}

#[test]
fn primitives_are_closed_and_face_outwards() {
    let b = unit_box();
    let cases = [
        (
            "cube",
            cuboid(b),
            f64::from(b.extent().x * b.extent().y * b.extent().z),
            1e-9,
        ),
        (
            "sphere",
            test_sphere(),
            4.0 / 3.0 * std::f64::consts::PI * 0.512,
            0.02,
        ),
        (
            "torus",
            test_torus(),
            2.0 * std::f64::consts::PI.powi(2) * 0.7 * 0.09,
            0.02,
        ),
    ];
    for (what, mesh, volume, tolerance) in cases {
        check_closed(&mesh.1).unwrap_or_else(|e| panic!("{what}: {e}"));
        let v = six_volume(&mesh) / 6.0;
        assert!(
            (v / volume - 1.0).abs() < tolerance,
            "{what}: volume {v}, expected {volume}"
        );
    }
    assert_eq!(cuboid(b).1.len(), 12);
}

#[test]
fn broken_meshes_are_refused_naming_the_fault() {
    let (vertices, triangles) = cuboid(unit_box());
    let refuse = |vertices: &[[f32; 3]], triangles: &[[u32; 3]]| {
        build(vertices, triangles).expect_err("refused")
    };

    let mut open = triangles.clone();
    let removed = open.remove(5);
    match refuse(&vertices, &open) {
        BuildError::OpenEdge { from, to, .. } => {
            assert!(removed.contains(&from) && removed.contains(&to))
        }
        e => panic!("{e}"),
    }

    let mut flipped = triangles.clone();
    flipped[3].swap(1, 2);
    match refuse(&vertices, &flipped) {
        BuildError::InconsistentOrientation { first, second, .. } => {
            assert!(first == 3 || second == 3)
        }
        e => panic!("{e}"),
    }

    let mut doubled = triangles.clone();
    doubled.extend_from_slice(&triangles[..2]);
    doubled.extend(triangles[..2].iter().map(|&[a, b, c]| [a, c, b]));
    assert!(matches!(
        refuse(&vertices, &doubled),
        BuildError::NonManifoldEdge { triangles: 4, .. }
    ));

    let mut nan = vertices.clone();
    nan[6][1] = f32::NAN;
    assert!(matches!(
        refuse(&nan, &triangles),
        BuildError::NonFiniteVertex { vertex: 6, .. }
    ));

    let mut out_of_range = triangles.clone();
    out_of_range[7][2] = 8;
    assert_eq!(
        refuse(&vertices, &out_of_range),
        BuildError::IndexOutOfRange {
            triangle: 7,
            index: 8,
            vertices: 8
        }
    );

    // A sliver: two coincident vertices make a closed but degenerate mesh.
    let mut squashed = vertices.clone();
    squashed[1] = squashed[0];
    assert!(matches!(
        refuse(&squashed, &triangles),
        BuildError::Degenerate { .. }
    ));
    assert_eq!(refuse(&vertices, &[]), BuildError::NoTriangles);
    let message = refuse(&vertices, &open).to_string();
    assert!(
        message.contains("not closed") && message.contains("triangle"),
        "{message}"
    );
}

/// A point on a sphere of radius 3 around the box and a direction at it roughly inwards.
fn ray_from_outside(rng: &mut TestRng) -> Ray {
    let origin = rng.unit_vector() * 3.0;
    let target = Vec3::new(
        rng.range(-1.2, 1.2) as f32,
        rng.range(-1.0, 1.0) as f32,
        rng.range(-0.7, 0.7) as f32,
    );
    Ray::new(origin, (target - origin).normalize())
}

#[test]
fn the_cube_mesh_crosses_where_the_box_does_bit_for_bit() {
    let b = unit_box();
    let buffers = built(&cuboid(b));
    let mesh = buffers.mesh();
    assert_eq!(mesh.bounds, b);
    let mut rng = TestRng::new(39);
    let mut entered = 0;
    for _ in 0..20_000 {
        let ray = ray_from_outside(&mut rng);
        let (want, got) = (Shape::entry(&b, &ray), mesh.entry(&ray));
        assert_eq!(want, got, "{ray:?}");
        let Some(hit) = got else { continue };
        entered += 1;
        // Onwards from the entry point, in any direction into the box.
        let mut dir = rng.unit_vector();
        if dir.dot(hit.normal) > 0.0 {
            dir = -dir;
        }
        for ray in [Ray::new(hit.point, ray.dir), Ray::new(hit.point, dir)] {
            assert_eq!(Shape::exit(&b, &ray), mesh.exit(&ray), "{ray:?}");
            assert_eq!(
                b.exit_distance(&ray).to_bits(),
                mesh.exit_distance(&ray).to_bits()
            );
        }
        // From a point inside.
        let inside = Ray::new(b.min + b.extent() * rng.unit_vector().abs(), dir);
        assert!(mesh.contains(inside.origin) && Shape::contains(&b, inside.origin));
        assert_eq!(Shape::exit(&b, &inside), mesh.exit(&inside), "{inside:?}");
    }
    assert!(entered > 10_000, "{entered}");
    assert!(!mesh.contains(Vec3::splat(2.0)));
}

/// Every distance along `ray` at which it crosses a triangle, in f64 by Möller and Trumbore's
/// test over all triangles (no BVH), with +1 for a crossing into the mesh and -1 out of it.
fn crossings_f64((vertices, triangles): &IndexedMesh, ray: &Ray) -> Vec<(f64, i32)> {
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let mut hits = Vec::new();
    for t in triangles {
        let [a, b, c] = t.map(|i| Vec3::from(vertices[i as usize]).as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det == 0.0 {
            continue;
        }
        let s = o - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let t = e2.dot(q) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 {
            // det = -d . (e1 x e2): positive when the ray runs against the outward normal.
            hits.push((t, if det > 0.0 { 1 } else { -1 }));
        }
    }
    hits.sort_by(|a, b| a.0.total_cmp(&b.0));
    hits
}

/// The total length of `ray` inside the mesh, in f64: the sum over the spans between a crossing
/// in and the next crossing out.
fn chord_f64(mesh: &IndexedMesh, ray: &Ray) -> Option<f64> {
    let hits = crossings_f64(mesh, ray);
    let mut total = 0.0;
    let mut depth = 0;
    let mut start = 0.0;
    for (t, sign) in hits {
        if depth == 0 && sign == 1 {
            start = t;
        }
        depth += sign;
        if depth < 0 {
            return None;
        }
        if depth == 0 {
            total += t - start;
        }
    }
    (depth == 0).then_some(total)
}

/// The length of `ray` inside `shape` as a path walks it: entry, exit, entry again...
fn chord_walked<S: Shape>(shape: &S, ray: &Ray) -> (f64, u32) {
    let mut ray = *ray;
    let (mut total, mut chords) = (0.0, 0);
    while let Some(entry) = shape.entry(&ray) {
        let inside = Ray::new(entry.point, ray.dir);
        let exit = shape.exit(&inside);
        total += f64::from(exit.point.distance(entry.point));
        chords += 1;
        ray = Ray::new(exit.point, ray.dir);
    }
    (total, chords)
}

/// The rays of the chord tests: from outside at the mesh, and through the torus's hole.
fn chord_rays(rng: &mut TestRng, n: usize) -> Vec<Ray> {
    let mut rays: Vec<Ray> = (0..n).map(|_| ray_from_outside(rng)).collect();
    rays.extend((0..n / 4).map(|_| {
        let origin = Vec3::new(
            -3.0,
            rng.range(-0.1, 0.1) as f32,
            rng.range(-0.2, 0.2) as f32,
        );
        let target = Vec3::new(
            3.0,
            rng.range(-0.1, 0.1) as f32,
            rng.range(-0.2, 0.2) as f32,
        );
        Ray::new(origin, (target - origin).normalize())
    }));
    rays
}

#[test]
fn walked_chords_through_sphere_and_torus_are_the_f64_chords() {
    let mut rng = TestRng::new(7);
    for (what, mesh) in [("sphere", test_sphere()), ("torus", test_torus())] {
        let buffers = built(&mesh);
        let shape = buffers.mesh();
        let mut two_chords = 0;
        for ray in chord_rays(&mut rng, 4000) {
            let want = chord_f64(&mesh, &ray).expect("a closed mesh");
            let (got, chords) = chord_walked(&shape, &ray);
            assert!((got - want).abs() < 1e-4, "{what} {ray:?}: {got} vs {want}");
            two_chords += (chords == 2) as u32;
        }
        if what == "torus" {
            assert!(two_chords > 1000, "{two_chords} rays cross the torus twice");
        }
    }
}

/// Rays from inside through every vertex and every edge's midpoint of the sphere (where two or
/// more triangles meet): each finds its way out, and from outside back in (no leak).
#[test]
fn rays_through_shared_edges_and_vertices_cross() {
    let mesh = test_sphere();
    let buffers = built(&mesh);
    let shape = buffers.mesh();
    let centre = Vec3::new(0.05, 0.0, -0.1);
    let mut targets: Vec<Vec3> = mesh.0.iter().map(|&v| Vec3::from(v)).collect();
    for t in &mesh.1 {
        for k in 0..3 {
            let (a, b) = (mesh.0[t[k] as usize], mesh.0[t[(k + 1) % 3] as usize]);
            targets.push((Vec3::from(a) + Vec3::from(b)) * 0.5);
        }
    }
    for target in targets {
        let dir = (target - centre).normalize();
        let out = Ray::new(centre, dir);
        let t = shape.nearest(&out, volpt_core::mesh::Crossing::Leaving);
        assert!(t.is_some(), "leaked out through {target:?}");
        let back = Ray::new(centre + dir * 2.0, -dir);
        assert!(shape.entry(&back).is_some(), "leaked in through {target:?}");
    }
}

type Absorber<S> =
    VolumeScene<HomogeneousMedium, NullBoundary, HenyeyGreenstein, ConstantEnvironment, S>;

/// An albedo-0 medium behind an index-matched boundary: a path survives only if it crosses every
/// chord without a collision, so a ray's expected radiance is `exp(-sigma_t * chord)` of the
/// chord computed in f64 above (the environment's radiance is 1).
#[test]
fn an_absorber_in_a_sphere_and_a_torus_transmits_exp_minus_sigma_chord() {
    const SIGMA_T: f32 = 1.3;
    const SAMPLES: u32 = 8000;
    let mut rng = TestRng::new(11);
    for (what, mesh) in [("sphere", test_sphere()), ("torus", test_torus())] {
        let buffers = built(&mesh);
        let scene: Absorber<_> = VolumeScene {
            camera: camera(),
            bounds: buffers.mesh(),
            medium: HomogeneousMedium {
                sigma_t: SIGMA_T,
                albedo: Spectrum::ZERO,
            },
            boundary: NullBoundary,
            phase: HenyeyGreenstein { g: 0.0 },
            environment: ConstantEnvironment(Spectrum::ONE),
            lights: volpt_core::Lights::NONE,
            settings: PathSettings::default(),
        };
        let mut worst: f64 = 0.0;
        // Over all rays: a small bias common to every ray shows here before in any one.
        let (mut total_error, mut total_variance) = (0.0, 0.0);
        for (i, ray) in chord_rays(&mut rng, 40).into_iter().enumerate() {
            let chord = chord_f64(&mesh, &ray).expect("a closed mesh");
            let expected = (-f64::from(SIGMA_T) * chord).exp();
            let mut sum = 0.0;
            for sample in 0..SAMPLES {
                let mut path = PathState::from_camera(&scene, 0, 0, sample, 0);
                path.ray = ray;
                path.rng = Rng::new(5, i as u32, sample);
                path.inside = false;
                trace(&scene, &mut path);
                sum += f64::from(path.radiance.x);
            }
            let mean = sum / f64::from(SAMPLES);
            let sd = (expected * (1.0 - expected) / f64::from(SAMPLES))
                .sqrt()
                .max(1e-9);
            let z = (mean - expected).abs() / sd;
            worst = worst.max(z);
            total_error += mean - expected;
            total_variance += sd * sd;
            assert!(
                z < Z_MAX,
                "{what} {ray:?}: {mean} vs exp(-sigma chord) = {expected}"
            );
        }
        let z = total_error / total_variance.sqrt();
        eprintln!("{what}: worst |z| of a ray {worst:.2}, z over all rays {z:.2}");
        assert!(z.abs() < Z_MAX, "{what}: z over all rays {z}");
    }
}

/// A furnace image's mean pixel (green channel, `spp` samples a pixel) and its z against 1, from
/// the pixels' spread.
fn furnace_mean_and_z(pixels: &[[f64; 3]], spp: u32) -> (f64, f64) {
    let samples: Vec<f64> = pixels.iter().map(|p| p[1] / f64::from(spp)).collect();
    let mean = samples.iter().sum::<f64>() / samples.len() as f64;
    let var = samples.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (samples.len() - 1) as f64;
    (mean, (mean - 1.0) / (var / samples.len() as f64).sqrt())
}

fn camera() -> PerspectiveCamera {
    PerspectiveCamera {
        origin: Vec3::new(0.3, 0.2, -4.0),
        axis_x: Vec3::new(-1.0, 0.0, 0.0),
        axis_y: Vec3::Y,
        axis_z: Vec3::Z,
        tan_half_fov: Vec2::new(0.35, 0.3),
        width: 24,
        height: 20,
        orthographic: false,
    }
}

/// Every pixel's sums of `spp` samples by the CPU's per-pixel loop.
fn image<S: volpt_core::Scene>(scene: &S, spp: u32) -> (Vec<[f64; 3]>, PathCounters) {
    let camera = scene.camera();
    let mut counters = PathCounters::default();
    let mut pixels = Vec::new();
    for py in 0..camera.height {
        for px in 0..camera.width {
            let mut sum = [0.0; 3];
            sample_pixel(scene, (px, py), 0..spp, 3, &mut sum, &mut counters);
            pixels.push(sum);
        }
    }
    (pixels, counters)
}

fn box_and_mesh<B: volpt_core::Bsdf + Copy>(boundary: B, estimator: Estimator, sigma_t: f32) {
    let b = unit_box();
    let buffers = built(&cuboid(b));
    let settings = PathSettings {
        estimator,
        ..PathSettings::default()
    };
    let boxed = VolumeScene {
        camera: camera(),
        bounds: b,
        medium: HomogeneousMedium {
            sigma_t,
            albedo: Spectrum::new(0.95, 0.8, 0.6),
        },
        boundary,
        phase: HenyeyGreenstein { g: 0.3 },
        environment: ConstantEnvironment(Spectrum::ONE),
        lights: volpt_core::Lights::NONE,
        settings,
    };
    let meshed = VolumeScene {
        bounds: buffers.mesh(),
        camera: boxed.camera,
        medium: boxed.medium,
        boundary,
        phase: boxed.phase,
        environment: boxed.environment,
        lights: volpt_core::Lights::NONE,
        settings,
    };
    // The factory's scene: either held as a run-time `BoundaryShape`.
    let as_run_time = |shape| VolumeScene {
        bounds: shape,
        camera: boxed.camera,
        medium: boxed.medium,
        boundary,
        phase: boxed.phase,
        environment: boxed.environment,
        lights: volpt_core::Lights::NONE,
        settings,
    };
    let as_run_time_device = |shape| VolumeScene {
        bounds: shape,
        lights: boxed.lights,
        camera: boxed.camera,
        medium: boxed.medium,
        boundary,
        phase: boxed.phase,
        environment: boxed.environment,
        settings,
    };
    let (want, want_counters) = image(&boxed, 8);
    for (what, (got, got_counters)) in [
        ("mesh", image(&meshed, 8)),
        (
            "BoundaryShape::Box",
            image(&as_run_time(BoundaryShape::Box(b)), 8),
        ),
        (
            "BoundaryShape::Mesh",
            image(&as_run_time(BoundaryShape::Mesh(buffers.mesh())), 8),
        ),
        // The GPU kernels' boundary, run here on the CPU.
        (
            "DeviceBoundary box",
            image(&as_run_time_device(DeviceBoundary::box_(b)), 8),
        ),
        (
            "DeviceBoundary mesh",
            image(
                &as_run_time_device(DeviceBoundary::mesh(&buffers.mesh())),
                8,
            ),
        ),
    ] {
        let differ = want.iter().zip(&got).filter(|(a, b)| a != b).count();
        assert_eq!(
            differ,
            0,
            "{what}, sigma_t {sigma_t}: {differ} of {} pixels differ",
            want.len()
        );
        assert_eq!(want_counters, got_counters, "{what}, sigma_t {sigma_t}");
    }
}

/// The 12-triangle cube traces the box's paths: the same images and counters, bit for bit, behind
/// every boundary kind and with next-event estimation, in a thin medium and in a dense one (where
/// most flights skip the ray cast by the distance grid).
#[test]
fn the_cube_mesh_renders_the_box_image_bit_for_bit() {
    for sigma_t in [2.0, 40.0] {
        for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
            box_and_mesh(NullBoundary, estimator, sigma_t);
            box_and_mesh(SmoothDielectric { eta: 1.5 }, estimator, sigma_t);
            box_and_mesh(
                RoughDielectric {
                    eta: 1.33,
                    distribution: Ggx { alpha: 0.3 },
                },
                estimator,
                sigma_t,
            );
        }
    }
}

/// The GPU kernels' boundary ([`DeviceBoundary`]: every flight casts its exit, a shadow ray's
/// convexity asked at run time, the ray cast out of line) traces the CPU's paths (the distance
/// grid's lazy exit) in a sphere and in a torus, where a ray crosses the mesh twice and shadow
/// rays cross several chords: the same images and counters, bit for bit, in a thin and a dense
/// medium, behind each boundary kind and with next-event estimation.
#[test]
fn the_kernels_mesh_boundary_traces_the_cpus_paths_in_a_sphere_and_a_torus() {
    fn check<B: volpt_core::Bsdf + Copy + std::fmt::Debug>(
        what: &str,
        mesh: &IndexedMesh,
        bsdf: B,
    ) {
        let buffers = built(mesh);
        for sigma_t in [1.5, 30.0] {
            for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
                let scene = |bounds| VolumeScene {
                    camera: camera(),
                    bounds,
                    lights: volpt_core::Lights::NONE,
                    medium: HomogeneousMedium {
                        sigma_t,
                        albedo: Spectrum::new(0.95, 0.8, 0.6),
                    },
                    boundary: bsdf,
                    phase: HenyeyGreenstein { g: 0.3 },
                    environment: ConstantEnvironment(Spectrum::ONE),
                    settings: PathSettings {
                        estimator,
                        ..PathSettings::default()
                    },
                };
                let cpu = scene(BoundaryShape::Mesh(buffers.mesh()));
                let device = VolumeScene {
                    bounds: DeviceBoundary::mesh(&buffers.mesh()),
                    lights: cpu.lights,
                    camera: cpu.camera,
                    medium: cpu.medium,
                    boundary: cpu.boundary,
                    phase: cpu.phase,
                    environment: cpu.environment,
                    settings: cpu.settings,
                };
                let (want, want_counters) = image(&cpu, 4);
                let (got, got_counters) = image(&device, 4);
                assert!(want.iter().any(|p| p[0] > 0.0));
                let differ = want.iter().zip(&got).filter(|(a, b)| a != b).count();
                let case = format!("{what}, {bsdf:?}, sigma_t {sigma_t}, {estimator:?}");
                assert_eq!(differ, 0, "{case}: {differ} pixels differ");
                assert_eq!(want_counters, got_counters, "{case}");
            }
        }
    }
    for (what, mesh) in [("sphere", test_sphere()), ("torus", test_torus())] {
        // Index-matched: next-event shadow rays cross the torus's chords.
        check(what, &mesh, NullBoundary);
        check(what, &mesh, SmoothDielectric { eta: 1.5 });
        check(
            what,
            &mesh,
            RoughDielectric {
                eta: 1.33,
                distribution: Ggx { alpha: 0.3 },
            },
        );
    }
}

/// The distance grid's bound from a point never exceeds the exit distance of any ray from it (so
/// a flight shorter than the bound truly collides inside), and it is large enough to be worth
/// having: in the sphere, the torus and the box, at random points and directions, it spares a
/// good part of the casts of flights a tenth of the shape's size long.
#[test]
fn the_distance_bound_never_exceeds_the_exit_and_spares_most_casts() {
    let mut rng = TestRng::new(3);
    for (what, mesh) in [
        ("sphere", test_sphere()),
        ("torus", test_torus()),
        ("box", cuboid(unit_box())),
    ] {
        let buffers = built(&mesh);
        let shape = buffers.mesh();
        let b = shape.bounds;
        let (mut inside, mut spared) = (0, 0);
        for _ in 0..20_000 {
            let p = b.min + (b.max - b.min) * Vec3::new(rng.f32(), rng.f32(), rng.f32());
            if !shape.contains(p) {
                continue;
            }
            inside += 1;
            let safe = shape.distance.at(p);
            let flight = 0.1 * (b.max - b.min).min_element();
            if flight < safe {
                spared += 1;
            }
            for _ in 0..8 {
                let ray = Ray::new(p, rng.unit_vector());
                let exit = shape.exit_distance(&ray);
                assert!(
                    safe <= exit,
                    "{what}: bound {safe} beyond the exit {exit} of {ray:?}"
                );
            }
        }
        let fraction = f64::from(spared) / f64::from(inside);
        eprintln!("{what}: {spared} of {inside} flights spared the cast ({fraction:.2})");
        // The points deeper than a flight are 49% of the sphere; a grid of 16 cells loses a
        // cell's part of that.
        assert!(fraction > 0.3, "{what}: only {fraction:.2} spared");
    }
}

/// The distance from `p` to triangle `[a, b, c]` in f64, independently of the grid's code: the
/// projection onto the plane where it falls inside, else the nearest of the three edges.
fn triangle_distance_f64(p: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    let n = (b - a).cross(c - a);
    let q = p - n * (p - a).dot(n) / n.length_squared();
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(u, v)| (v - u).cross(q - u).dot(n) >= 0.0);
    if inside {
        return (p - q).length();
    }
    [(a, b), (b, c), (c, a)]
        .iter()
        .map(|&(u, v)| {
            let t = ((p - u).dot(v - u) / (v - u).length_squared()).clamp(0.0, 1.0);
            (p - (u + (v - u) * t)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

fn surface_distance_f64((vertices, triangles): &IndexedMesh, p: DVec3) -> f64 {
    triangles
        .iter()
        .map(|t| triangle_distance_f64(p, t.map(|i| Vec3::from(vertices[i as usize]).as_dvec3())))
        .fold(f64::INFINITY, f64::min)
}

/// Every value of the distance grid is a lower bound of the distance from its cell's centre to
/// the surface (brute force over all triangles, f64; to f64 rounding), and so is the bound the
/// lookup gives at random points (strictly);
/// and the grid is tight: within the refined band it is the distance (to f32 rounding), and
/// elsewhere less than a cell's diagonal below it. Shapes: the sphere, the torus, the box, a
/// rotated box and an octahedron (large slanted triangles cross many cells).
#[test]
fn the_distance_grid_bounds_the_brute_force_distance_from_below_and_tightly() {
    use volpt_core::mesh::distance::NEAR_CELLS;
    let mut rng = TestRng::new(11);
    let rotated = {
        let (vertices, triangles) = cuboid(unit_box());
        let (s, c) = (0.6f32.sin(), 0.6f32.cos());
        let turn = |[x, y, z]: [f32; 3]| {
            [
                c * x - s * y,
                s * x * 0.8 + c * y * 0.8 + 0.6 * z,
                -0.6 * s * x - 0.6 * c * y + 0.8 * z,
            ]
        };
        (vertices.into_iter().map(turn).collect(), triangles)
    };
    for (what, mesh, cells) in [
        ("sphere", test_sphere(), 16),
        ("torus", test_torus(), 20),
        ("box", cuboid(unit_box()), 16),
        ("rotated box", rotated, 12),
        ("octahedron", sphere([0.0; 3], 1.0, 2, 4), 16),
    ] {
        let buffers = build(&mesh.0, &mesh.1).expect("a closed mesh builds");
        let res = resolution_for(buffers.bounds, cells);
        let buffers = buffers.with_distances(res);
        let grid = buffers.mesh().distance;
        let [rx, ry, rz] = grid.res;
        let (diagonal, near) = (
            f64::from(grid.cell.length()),
            f64::from(grid.cell.max_element()) * NEAR_CELLS,
        );
        let mut worst_slack: f64 = 0.0;
        for z in 0..rz {
            for y in 0..ry {
                for x in 0..rx {
                    let centre =
                        grid.min + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * grid.cell;
                    let exact = surface_distance_f64(&mesh, centre.as_dvec3());
                    let value = f64::from(grid.values[((z * ry + y) * rx + x) as usize]);
                    // Two f64 computations of the same distance may differ in their last bits;
                    // the lookup's margin (`at`, checked below) is far larger.
                    assert!(
                        value <= exact * (1.0 + 1e-12),
                        "{what}: cell ({x}, {y}, {z}) holds {value}, beyond its distance {exact}"
                    );
                    let allowed = if exact < near {
                        1e-6 * (1.0 + exact)
                    } else {
                        diagonal * 1.001
                    };
                    assert!(
                        exact - value <= allowed,
                        "{what}: cell ({x}, {y}, {z}) holds {value}, loose by {} (distance {exact})",
                        exact - value
                    );
                    worst_slack = worst_slack.max(exact - value);
                }
            }
        }
        let b = buffers.bounds;
        for _ in 0..2000 {
            let p = b.min + (b.max - b.min) * Vec3::new(rng.f32(), rng.f32(), rng.f32());
            let (bound, exact) = (grid.at(p), surface_distance_f64(&mesh, p.as_dvec3()));
            assert!(
                f64::from(bound) <= exact,
                "{what}: bound {bound} at {p} beyond its distance {exact}"
            );
        }
        eprintln!("{what}: {rx}x{ry}x{rz} cells, at most {worst_slack:.4} below the distance (cell diagonal {diagonal:.4})");
    }
}

/// The white furnace inside the torus: albedo 1 behind an index-matched boundary under a constant
/// environment of radiance 1 returns exactly 1 on average, with path tracing and with next-event
/// estimation, whose shadow rays must cross every chord of the torus (one through the hole meets
/// the medium again).
#[test]
fn the_furnace_in_a_torus_returns_the_light_with_and_without_next_event_estimation() {
    const SPP: u32 = 256;
    let mesh = test_torus();
    let buffers = built(&mesh);
    for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
        let scene: Absorber<_> = VolumeScene {
            camera: camera(),
            bounds: buffers.mesh(),
            medium: HomogeneousMedium {
                sigma_t: 2.0,
                albedo: Spectrum::ONE,
            },
            boundary: NullBoundary,
            phase: HenyeyGreenstein { g: 0.3 },
            environment: ConstantEnvironment(Spectrum::ONE),
            lights: volpt_core::Lights::NONE,
            settings: PathSettings {
                estimator,
                ..PathSettings::default()
            },
        };
        let (pixels, counters) = image(&scene, SPP);
        let n = counters.paths as f64;
        assert_eq!(counters.truncated, 0);
        let (mean, z) = furnace_mean_and_z(&pixels, SPP);
        eprintln!("{estimator:?}: mean {mean} over {n} paths, z {z:.2}");
        assert!(z.abs() < Z_MAX, "{estimator:?}: mean {mean}, z {z}");
    }
}

/// A BVH large enough that its top levels are built as separate subtrees and concatenated is
/// well formed: from the root, every child's box lies in its parent's, every leaf's triangles in
/// its box, every triangle is in exactly one leaf, and no leaf is deeper than the traversal's
/// stack; and rays cast through it cross where the f64 brute force says.
#[test]
fn a_bvh_of_concatenated_subtrees_is_well_formed() {
    use volpt_core::mesh::{BvhNode, MAX_BVH_DEPTH};
    let mesh = sphere([0.1, -0.2, 0.0], 1.0, 140, 280);
    assert!(
        mesh.1.len() > 2 * (1 << 15),
        "too small to be split into subtrees"
    );
    let buffers = build(&mesh.0, &mesh.1).expect("closed");
    let nodes = &buffers.nodes;
    let inside = |inner: ([f32; 3], [f32; 3]), outer: &BvhNode| {
        (0..3).all(|k| inner.0[k] >= outer.min[k] && inner.1[k] <= outer.max[k])
    };
    let mut seen = vec![0u32; buffers.triangles.len()];
    let mut stack = vec![(0u32, 1usize)];
    while let Some((i, depth)) = stack.pop() {
        let n = nodes[i as usize];
        assert!(depth <= MAX_BVH_DEPTH, "node {i} at depth {depth}");
        if n.count > 0 {
            for t in n.first..n.first + n.count {
                let v = buffers.triangles[t as usize].v;
                let lo = [0, 1, 2].map(|k| v[0][k].min(v[1][k]).min(v[2][k]));
                let hi = [0, 1, 2].map(|k| v[0][k].max(v[1][k]).max(v[2][k]));
                assert!(inside((lo, hi), &n), "triangle {t} outside leaf {i}");
                seen[t as usize] += 1;
            }
        } else {
            for child in [i + 1, n.first] {
                let c = nodes[child as usize];
                assert!(
                    inside((c.min, c.max), &n),
                    "node {child} outside its parent {i}"
                );
                stack.push((child, depth + 1));
            }
        }
    }
    assert!(
        seen.iter().all(|&n| n == 1),
        "a triangle in no leaf or in two"
    );
    let shape = buffers.mesh();
    let mut rng = TestRng::new(5);
    for ray in chord_rays(&mut rng, 200) {
        let walked = chord_walked(&shape, &ray).0;
        let exact = chord_f64(&mesh, &ray).unwrap_or(0.0);
        assert!(
            (walked - exact).abs() < 1e-4,
            "{ray:?}: chord {walked}, f64 {exact}"
        );
    }
}

/// The radial unit normals of `mesh`'s vertices about `center` at each triangle's corners: a
/// sphere's exact normals, strongly bent against the faces of a coarse one.
fn radial_normals((vertices, triangles): &IndexedMesh, center: Vec3) -> Vec<[[f32; 3]; 3]> {
    triangles
        .iter()
        .map(|t| {
            t.map(|i| {
                (Vec3::from(vertices[i as usize]) - center)
                    .normalize()
                    .to_array()
            })
        })
        .collect()
}

#[test]
fn the_shading_normal_interpolates_the_corner_normals_and_stays_in_the_geometric_hemisphere() {
    use volpt_core::mesh::{shading_normal, MeshTriangle};
    let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let tri = MeshTriangle {
        v,
        normal: [0.0, 0.0, 1.0],
        offset: 0.0,
    };
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let corners = [[s, 0.0, s], [0.0, s, s], [0.0, 0.0, 1.0]];
    for (k, p) in v.iter().enumerate() {
        let n = shading_normal(&tri, &corners, Vec3::from(*p));
        assert!(
            (n - Vec3::from(corners[k])).length() < 1e-6,
            "corner {k}: {n}"
        );
    }
    let centroid = Vec3::new(1.0 / 3.0, 1.0 / 3.0, 0.0);
    let expected =
        (Vec3::from(corners[0]) + Vec3::from(corners[1]) + Vec3::from(corners[2])).normalize();
    let n = shading_normal(&tri, &corners, centroid);
    assert!(
        (n - expected).length() < 1e-6,
        "centroid: {n} vs {expected}"
    );
    // A point a rounding error outside the triangle is on its edge.
    let n = shading_normal(&tri, &corners, Vec3::new(0.5, -1e-7, 0.0));
    let edge = (Vec3::from(corners[0]) + Vec3::from(corners[1])).normalize();
    assert!((n - edge).length() < 1e-5, "edge: {n} vs {edge}");
    // Corner normals that sum to a direction below the surface: the geometric normal.
    let below = [[1.0, 0.0, -0.1], [1.0, 0.0, -0.1], [1.0, 0.0, -0.1]];
    assert_eq!(shading_normal(&tri, &below, centroid), Vec3::Z);
}

#[test]
fn vertex_normals_are_put_in_bvh_order_and_bad_ones_refused() {
    let mesh = sphere([0.0; 3], 1.0, 6, 12);
    let normals = radial_normals(&mesh, Vec3::ZERO);
    let buffers = build(&mesh.0, &mesh.1)
        .unwrap()
        .with_vertex_normals(&normals)
        .unwrap();
    for (i, &input) in buffers.order.iter().enumerate() {
        let expected = normals[input as usize];
        for (corner, n) in buffers.normals[i].iter().enumerate() {
            assert!((Vec3::from(*n) - Vec3::from(expected[corner])).length() < 1e-6);
        }
    }
    let mut bad = normals.clone();
    bad[5][2] = [0.0; 3];
    let err = build(&mesh.0, &mesh.1)
        .unwrap()
        .with_vertex_normals(&bad)
        .unwrap_err();
    assert_eq!(
        err,
        BuildError::BadNormal {
            triangle: 5,
            corner: 2,
            normal: [0.0; 3]
        }
    );
    assert!(matches!(
        build(&mesh.0, &mesh.1)
            .unwrap()
            .with_vertex_normals(&normals[1..]),
        Err(BuildError::NormalCount { .. })
    ));
}

/// The white furnace behind a dielectric surface shaded with bent vertex normals: albedo 1 inside
/// a coarse sphere whose radial vertex normals lean up to ~40 degrees from its faces, an
/// environment of radiance 1 (constant, and a uniform map, which next-event estimation samples at
/// the rough boundary). With face normals the smooth surface's furnace returns exactly 1 (the
/// rough one's single-scattering microfacets lose some); shading normals must not create light
/// (the mean stays <= 1 within the noise), and the directions dropped because their side
/// contradicts their lobe must not lose much of it (smooth 0.977, rough 0.906 at these
/// settings). Planted defect seen failing: the BSDF given the shading normal where it puts the ray
/// on the other side than the geometric normal (rough 0.896).
#[test]
fn shading_normals_create_no_energy_in_the_white_furnace() {
    const SPP: u32 = 64;
    let center = Vec3::new(0.05, 0.0, -0.1);
    let mesh = sphere(center.as_dvec3().to_array(), 0.8, 4, 8);
    let buffers = built(&mesh)
        .with_vertex_normals(&radial_normals(&mesh, center))
        .unwrap();
    let white = [1.0f32; 3 * 4 * 2];
    let mut map = LatLongEnvironment::new(
        &white,
        4,
        2,
        LatLongRows::PoleToPole,
        [Vec3::X, Vec3::Y, Vec3::Z],
        1.0,
    );
    let mut distribution = vec![0.0; LatLongEnvironment::distribution_len(4, 2)];
    map.fill_distribution(&mut distribution);
    map.distribution = &distribution;

    fn furnace<S: Shape + Copy, B: volpt_core::Bsdf + Copy, E: volpt_core::Environment + Copy>(
        what: &str,
        shape: S,
        boundary: B,
        environment: E,
        estimator: Estimator,
    ) {
        let scene = VolumeScene {
            camera: camera(),
            bounds: shape,
            medium: HomogeneousMedium {
                sigma_t: 2.0,
                albedo: Spectrum::ONE,
            },
            boundary,
            phase: HenyeyGreenstein { g: 0.3 },
            environment,
            lights: volpt_core::Lights::NONE,
            settings: PathSettings {
                estimator,
                ..PathSettings::default()
            },
        };
        let (pixels, counters) = image(&scene, SPP);
        assert_eq!(counters.truncated, 0, "{what}");
        // The camera's rays that miss the sphere see the environment: 1 exactly.
        let (mean, z) = furnace_mean_and_z(&pixels, SPP);
        eprintln!("{what} {estimator:?}: mean {mean}, z against 1 {z:.2}");
        assert!(
            z < Z_MAX,
            "{what} {estimator:?}: light created, mean {mean}, z {z}"
        );
        assert!(
            mean > 0.9,
            "{what} {estimator:?}: mean {mean}, too much dropped"
        );
    }
    let smooth = SmoothDielectric { eta: 1.5 };
    let rough = RoughDielectric {
        eta: 1.5,
        distribution: Ggx { alpha: 0.3 },
    };
    let constant = ConstantEnvironment(Spectrum::ONE);
    let mesh = buffers.mesh();
    for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
        furnace("smooth", mesh, smooth, constant, estimator);
        furnace("rough", mesh, rough, constant, estimator);
        furnace("rough, map", mesh, rough, map, estimator);
        // The same mesh as the CPU's run-time boundary.
        furnace(
            "rough, map, BoundaryShape",
            BoundaryShape::Mesh(mesh),
            rough,
            map,
            estimator,
        );
    }
}

/// A point of `ray` half way to the next surface it crosses, which is inside the mesh exactly
/// when the ray's start is; none where that surface is nearer than rounding lets `contains` tell
/// (a start a rounding error off the surface, at an edge).
fn point_ahead(mesh: &volpt_core::mesh::TriangleMesh<'_>, ray: &Ray) -> Option<Vec3> {
    const NEAR: f32 = 1e-4;
    let moved = Ray::new(ray.at(NEAR), ray.dir);
    match mesh.nearest(&moved, volpt_core::mesh::Crossing::Any) {
        Some((t, _)) if t < NEAR => None,
        Some((t, _)) => Some(ray.at(NEAR + 0.5 * t)),
        None => Some(ray.at(2.0 * NEAR)),
    }
}

/// Where vertex normals are bent, a direction the BSDF samples about the shading normal may lie on
/// the other side of the geometric surface than its lobe says: a "reflection" into the medium, a
/// "transmission" that stays out. Such directions are dropped, so a path's `inside` always says
/// which side of the surface it is on: after every step of every path, the point just ahead of
/// the ray is inside the mesh exactly when the path says it is inside. Planted defect seen
/// failing: the directions kept (and the furnace above cannot see it: white light leaks
/// both ways alike).
#[test]
fn with_shading_normals_a_path_stays_on_the_side_of_the_surface_it_says() {
    let center = Vec3::new(0.05, 0.0, -0.1);
    let mesh = sphere(center.as_dvec3().to_array(), 0.8, 4, 8);
    let buffers = built(&mesh)
        .with_vertex_normals(&radial_normals(&mesh, center))
        .unwrap();
    let scene = VolumeScene {
        camera: camera(),
        bounds: buffers.mesh(),
        medium: HomogeneousMedium {
            sigma_t: 2.0,
            albedo: Spectrum::ONE,
        },
        boundary: RoughDielectric {
            eta: 1.5,
            distribution: Ggx { alpha: 0.3 },
        },
        phase: HenyeyGreenstein { g: 0.3 },
        environment: ConstantEnvironment(Spectrum::ONE),
        lights: volpt_core::Lights::NONE,
        settings: PathSettings::default(),
    };
    let shape = buffers.mesh();
    let (mut steps, mut wrong, mut unclear) = (0u32, 0u32, 0u32);
    for sample in 0..16 {
        for py in 0..scene.camera.height {
            for px in 0..scene.camera.width {
                let mut path = PathState::from_camera(&scene, px, py, sample, 3);
                while path.alive {
                    volpt_core::path::step(&scene, &mut path);
                    if !path.alive {
                        continue;
                    }
                    match point_ahead(&shape, &path.ray) {
                        Some(ahead) => {
                            steps += 1;
                            wrong += u32::from(shape.contains(ahead) != path.inside);
                        }
                        None => unclear += 1,
                    }
                }
            }
        }
    }
    eprintln!("{wrong} of {steps} steps on the wrong side, {unclear} too near a surface to tell");
    assert!(steps > 10_000 && unclear < steps / 100);
    assert_eq!(
        wrong, 0,
        "{wrong} of {steps} steps on the other side than the path says"
    );
}

/// The BVH walk (its stack, the far children skipped once a nearer crossing is known, the
/// cheap rejections before the edge functions) finds the crossing a scan of every triangle in
/// order finds: the same distance to the bit and a triangle of the same plane, for every kind of
/// crossing, from outside, from inside and from points on the surface, in the sphere and the
/// torus. The scan is the same mesh with one leaf holding every triangle.
#[test]
fn the_bvh_walk_finds_what_a_scan_of_every_triangle_finds() {
    use volpt_core::mesh::{BvhNode, Crossing, TriangleMesh};
    let mut rng = TestRng::new(13);
    for (what, mesh) in [("sphere", test_sphere()), ("torus", test_torus())] {
        let buffers = built(&mesh);
        let walked = buffers.mesh();
        let leaf = [BvhNode {
            min: walked.bounds.min.to_array(),
            first: 0,
            max: walked.bounds.max.to_array(),
            count: walked.triangles.len() as u32,
        }];
        let scan = TriangleMesh {
            nodes: &leaf,
            ..walked
        };
        let mut found = 0;
        for ray in chord_rays(&mut rng, 3000) {
            let inside = Vec3::new(
                rng.range(-0.6, 0.6) as f32,
                rng.range(-0.6, 0.6) as f32,
                rng.range(-0.3, 0.3) as f32,
            );
            let on_surface = walked
                .entry(&ray)
                .map(|hit| Ray::new(hit.point, rng.unit_vector()));
            let rays = [
                Some(ray),
                Some(Ray::new(inside, rng.unit_vector())),
                on_surface,
            ];
            for ray in rays.into_iter().flatten() {
                for crossing in [Crossing::Entering, Crossing::Leaving, Crossing::Any] {
                    let (want, got) =
                        (scan.nearest(&ray, crossing), walked.nearest(&ray, crossing));
                    let plane = |(t, i): (f32, u32)| {
                        let tri = walked.triangles[i as usize];
                        (
                            t.to_bits(),
                            tri.normal.map(f32::to_bits),
                            tri.offset.to_bits(),
                        )
                    };
                    assert_eq!(
                        want.map(plane),
                        got.map(plane),
                        "{what} {crossing:?} {ray:?}"
                    );
                    found += got.is_some() as u32;
                }
            }
        }
        assert!(found > 10_000, "{what}: {found} crossings found");
    }
}
