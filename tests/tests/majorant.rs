//! The majorant of delta tracking, as the render factory builds it: tracking through extinction
//! that reaches the majorant against the analytic transmittance, and a property test that no
//! lookup the renderer can make (any grid, convention, box, scale, position) exceeds it. A majorant
//! below the true maximum silently caps the extinction there (Woodcock's acceptance probability
//! cannot exceed 1), which only shows where the density is at its maximum.

use glam::DVec3;
use volpt_core::rng::Rng;
use volpt_core::tracking::{delta_tracking, FreeFlight};
use volpt_core::{Medium, Ray, Vec3};
use volpt_render::{SceneVisitor, Variant};
use volpt_scene::description::*;
use volpt_tests::reference::RefMedium;
use volpt_tests::{cube_scene, with_core_scene};

/// Delta tracking from `origin` along `dir` up to `t_max`, `paths` times: the fraction that gets
/// through without a real collision.
struct Escapes {
    origin: Vec3,
    dir: Vec3,
    t_max: f32,
    paths: u32,
}

impl SceneVisitor for Escapes {
    type Output = f64;
    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> f64 {
        let ray = Ray::new(self.origin, self.dir);
        let mut steps = 0;
        let escaped = (0..self.paths)
            .filter(|&i| {
                let mut rng = Rng::new(17, i, 0);
                let flight = delta_tracking(
                    scene.medium(),
                    &ray,
                    self.t_max,
                    &mut rng,
                    &mut steps,
                    u32::MAX,
                );
                matches!(flight, FreeFlight::Escaped)
            })
            .count();
        escaped as f64 / self.paths as f64
    }
}

/// A 6^3 grid whose samples with y and z indices in 1..=4 (a rod along x, through the box's
/// centre) are at the maximum 2.0; the others lie between 0.2 and 1.4.
fn rod_grid(convention: GridConvention) -> GridDesc {
    let n = 6u32;
    let mut data = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let rod = (1..=4).contains(&y) && (1..=4).contains(&z);
                data.push(if rod {
                    2.0
                } else {
                    0.2 + 0.3 * ((x + 2 * y + 3 * z) % 5) as f32
                });
            }
        }
    }
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution: [n; 3],
        channels: 1,
        bounds: Bounds {
            min: [-0.5; 3],
            max: [0.5; 3],
        },
        convention,
        data,
    }
}

/// Along the rod the extinction equals the majorant everywhere, so the escape probability is
/// `exp(-scale * 2 * length)` exactly; off the rod it is `exp(-tau)` with tau from the independent
/// reference grid. 200 000 tracked rays per line: 5 binomial standard deviations are about 0.5% of
/// the transmittance, a 10% low majorant moves it by more than 10%.
#[test]
fn delta_tracking_matches_analytic_transmittance_where_density_reaches_the_majorant() {
    const PATHS: u32 = 200_000;
    for convention in [GridConvention::Vertex, GridConvention::Cell] {
        let medium = MediumDesc {
            density: DensityDesc::Grid(rod_grid(convention)),
            scale: 0.6,
            albedo: AlbedoDesc::Constant([0.5; 3]),
            phase: PhaseDesc::Isotropic,
            lookup: Default::default(),
            storage: Default::default(),
        };
        let desc = cube_scene(4, 4, medium, BsdfDesc::Null, 1.0);
        let reference = RefMedium::new(&desc);
        let lines = [
            // Along the rod's axis: analytic.
            (DVec3::new(-0.5, 0.0, 0.0), DVec3::X),
            (DVec3::new(0.5, 0.02, -0.03), -DVec3::X),
            // Across the grid, through the rod and the varying samples.
            (
                DVec3::new(-0.5, -0.4, -0.3),
                DVec3::new(1.0, 0.8, 0.55).normalize(),
            ),
        ];
        for (origin, dir) in lines {
            let (_, t_max) = reference.bounds.interval(origin, dir).expect("line in box");
            let tau = reference.optical_depth(origin, dir, (0.0, t_max), 20_000);
            let expected = (-tau).exp();
            let measured = with_core_scene(
                &desc,
                Escapes {
                    origin: origin.as_vec3(),
                    dir: dir.as_vec3(),
                    t_max: t_max as f32,
                    paths: PATHS,
                },
            );
            let sd = (expected * (1.0 - expected) / PATHS as f64).sqrt();
            assert!(
                (measured - expected).abs() <= 5.0 * sd,
                "{convention:?}, from {origin} along {dir}: escaped {measured}, \
                 exp(-tau) = {expected} (sd {sd})"
            );
        }
        // On the rod's axis the reference agrees with the closed form.
        let tau = reference.optical_depth(DVec3::new(-0.5, 0.0, 0.0), DVec3::X, (0.0, 1.0), 100);
        let sigma_max = 0.6f32 as f64 * 2.0;
        assert!((tau - sigma_max).abs() < 1e-12, "tau on the rod {tau}");
        assert_eq!(reference.max_sigma_t(), sigma_max);
    }
}

/// SplitMix64: reproducible cases without a dependency.
struct Cases(u64);

impl Cases {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    fn below(&mut self, n: u32) -> u32 {
        (self.next() % n as u64) as u32
    }
}

/// Sample values as loaders produce them: zeros, plateaus of one value, and arbitrary floats.
fn random_value(cases: &mut Cases, top: f32) -> f32 {
    match cases.below(4) {
        0 => 0.0,
        1 => top,
        _ => cases.range(0.0, top),
    }
}

fn random_grid(cases: &mut Cases, channels: u32) -> GridDesc {
    let resolution = [0; 3].map(|_| 1 + cases.below(6));
    let count = resolution.iter().product::<u32>() * channels;
    let top = [1e-3, 1.0, 37.0, 1e4][cases.below(4) as usize];
    let data = (0..count).map(|_| random_value(cases, top)).collect();
    // Grid boxes inside, around, or straddling the boundary's unit cube.
    let min = [0; 3].map(|_| cases.range(-0.8, 0.2));
    let max = min.map(|m| m + cases.range(0.05, 1.2));
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution,
        channels,
        bounds: Bounds { min, max },
        convention: if cases.below(2) == 0 {
            GridConvention::Vertex
        } else {
            GridConvention::Cell
        },
        data,
    }
}

/// The largest `sigma_t(p)` over `points` (as the trackers read it, a stochastic lookup with
/// random bits) and the majorant, or the first point where a lookup is not a
/// finite non-negative number.
struct LookupBound<'a> {
    points: &'a [Vec3],
}

impl SceneVisitor for LookupBound<'_> {
    type Output = Result<(f32, f32), Vec3>;
    fn visit<S: volpt_render::RenderScene>(self, scene: &S) -> Self::Output {
        let majorant = scene.medium().majorant();
        let mut largest = 0.0f32;
        for (i, &p) in self.points.iter().enumerate() {
            // Random bits for a stochastic lookup (every other lookup ignores them).
            let bits = (i as u64 + 1)
                .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                .rotate_left(29);
            let s = scene.medium().sigma_t_random(p, bits);
            if !(s.is_finite() && s >= 0.0) {
                return Err(p);
            }
            largest = largest.max(s);
        }
        Ok((largest, majorant))
    }
}

/// Positions a tracker can reach and the special ones a grid treats separately: uniform in and
/// around both boxes, on their faces, edges and corners, and exactly at the samples.
fn probe_points(cases: &mut Cases, grid: &GridDesc) -> Vec<Vec3> {
    let (lo, hi) = (
        Vec3::from_array(grid.bounds.min).min(Vec3::splat(-0.5)),
        Vec3::from_array(grid.bounds.max).max(Vec3::splat(0.5)),
    );
    let mut points = Vec::new();
    for _ in 0..3000 {
        let mut p = Vec3::new(
            cases.range(lo.x - 0.1, hi.x + 0.1),
            cases.range(lo.y - 0.1, hi.y + 0.1),
            cases.range(lo.z - 0.1, hi.z + 0.1),
        );
        // Snap some coordinates onto the grid box's faces.
        for a in 0..3 {
            match cases.below(6) {
                0 => p[a] = grid.bounds.min[a],
                1 => p[a] = grid.bounds.max[a],
                _ => {}
            }
        }
        points.push(p);
    }
    let [nx, ny, nz] = grid.resolution;
    let extent = Vec3::from_array(grid.bounds.max) - Vec3::from_array(grid.bounds.min);
    for (x, y, z) in
        (0..nx).flat_map(|x| (0..ny).flat_map(move |y| (0..nz).map(move |z| (x, y, z))))
    {
        let index = Vec3::new(x as f32, y as f32, z as f32);
        let res = Vec3::new(nx as f32, ny as f32, nz as f32);
        let s = match grid.convention {
            GridConvention::Vertex => index / (res - 1.0).max(Vec3::ONE),
            GridConvention::Cell => (index + 0.5) / res,
        };
        points.push(Vec3::from_array(grid.bounds.min) + s * extent);
    }
    points
}

/// 400 random media through the render factory, each read by every lookup (trilinear, nearest,
/// texture, half-precision texture): no extinction lookup exceeds the majorant it builds (with grid
/// density, grid albedo, and a constant density under a grid albedo), the majorant is no larger
/// than `scale * max`, and the lookups reach it (so `sigma_t` is the extinction the majorant
/// bounds, also where tracking never asks for it: homogeneous media). The majorant is built from
/// the samples, so half-precision texels must round toward zero: one rounded up would lie above it.
#[test]
fn majorant_bounds_every_lookup_the_renderer_can_make() {
    let mut cases = Cases(2026);
    for case in 0..400 {
        let density = random_grid(&mut cases, 1);
        let scale = [1.0, cases.range(0.01, 5.0), 1e3][cases.below(3) as usize];
        let albedo = match cases.below(3) {
            0 => AlbedoDesc::Grid(random_grid(&mut cases, 3)),
            _ => AlbedoDesc::Constant([0.8; 3]),
        };
        let constant_density = cases.below(5) == 0;
        let points = probe_points(&mut cases, &density);
        for lookup in [
            GridLookup::Trilinear,
            GridLookup::Nearest,
            GridLookup::Texture,
            GridLookup::TextureHalf,
            GridLookup::Stochastic,
        ] {
            let medium = MediumDesc {
                density: if constant_density {
                    DensityDesc::Constant(density.max_value())
                } else {
                    DensityDesc::Grid(density.clone())
                },
                scale,
                albedo: albedo.clone(),
                phase: PhaseDesc::Isotropic,
                lookup,
                storage: Default::default(),
            };
            let desc = cube_scene(2, 2, medium, BsdfDesc::Null, 1.0);
            let variant = Variant::of(&desc);
            let (largest, majorant) = with_core_scene(&desc, LookupBound { points: &points })
                .unwrap_or_else(|p| {
                    panic!("case {case} ({variant}, {lookup:?}): sigma_t({p}) is not finite")
                });
            assert!(
                largest <= majorant,
                "case {case} ({variant}, {lookup:?}): sigma_t reaches {largest} above the \
                 majorant {majorant} (grid {:?}, scale {scale})",
                density.resolution
            );
            let expected = scale * density.max_value();
            assert!(
                majorant <= expected * (1.0 + 1e-6),
                "case {case} ({variant}, {lookup:?}): majorant {majorant} looser than scale * max \
                 = {expected}"
            );
            // The probes include the largest sample's position (and, for a constant density,
            // points inside the box), where the extinction is the majorant up to rounding: of
            // the interpolation, and for half texels of the sample (at most 2^-10 below it).
            let rounding = if lookup == GridLookup::TextureHalf {
                1e-3
            } else {
                1e-4
            };
            assert!(
                largest >= majorant * (1.0 - rounding),
                "case {case} ({variant}, {lookup:?}): no lookup reaches the majorant {majorant} \
                 (largest {largest})"
            );
        }
    }
}
