//! Ray-box entry and exit against an f64 slab test, exact edge and corner cases, signed zeros, and
//! the orthonormal frame.
//!
//! Tolerances: distances and points are f32 (relative rounding ~1e-7 per operation on coordinates
//! of size <= 10), so 1e-5 absolute is a hundred ulps; faces, normals and snapped coordinates are
//! exact by construction and compared exactly.

mod common;

use common::*;
use volpt_core::frame::Frame;
use volpt_core::geometry::BoxHit;
use volpt_core::{Aabb, Ray, Vec3};

fn unit_box() -> Aabb {
    // Asymmetric, so that axis or min/max mix-ups show.
    Aabb::new(Vec3::new(-1.0, -2.0, 0.0), Vec3::new(1.0, 2.0, 4.0))
}

fn axis(i: usize) -> Vec3 {
    let mut v = Vec3::ZERO;
    v[i] = 1.0;
    v
}

/// f64 slab test: (t_enter, t_leave, entry axis, exit axis), or None when the line misses a slab it
/// runs parallel to.
fn slabs(b: &Aabb, ray: &Ray) -> Option<(f64, f64, usize, usize)> {
    let (mut t_enter, mut t_leave) = (f64::NEG_INFINITY, f64::INFINITY);
    let (mut enter_axis, mut leave_axis) = (usize::MAX, usize::MAX);
    for i in 0..3 {
        let (o, d) = (ray.origin[i] as f64, ray.dir[i] as f64);
        let (lo, hi) = (b.min[i] as f64, b.max[i] as f64);
        if d == 0.0 {
            if o < lo || o > hi {
                return None;
            }
            continue;
        }
        let (t0, t1) = ((lo - o) / d, (hi - o) / d);
        let (near, far) = (t0.min(t1), t0.max(t1));
        if near > t_enter {
            t_enter = near;
            enter_axis = i;
        }
        if far < t_leave {
            t_leave = far;
            leave_axis = i;
        }
    }
    Some((t_enter, t_leave, enter_axis, leave_axis))
}

/// The hit lies on the box, on the plane of its normal's face, at `ray.at(t)`.
fn check_on_face(b: &Aabb, ray: &Ray, hit: &BoxHit, outward: bool) {
    assert!(hit.t.is_finite() && hit.t >= 0.0, "{ray:?}: {hit:?}");
    assert_finite_vec(hit.point, "hit point");
    assert!(b.contains(hit.point), "{ray:?}: {hit:?} not on the box");
    let a = hit.normal.abs().max_position();
    assert_eq!(
        hit.normal.abs(),
        axis(a),
        "{ray:?}: normal {:?}",
        hit.normal
    );
    let face = if hit.normal[a] > 0.0 {
        b.max[a]
    } else {
        b.min[a]
    };
    assert_eq!(hit.point[a], face, "{ray:?}: {hit:?} not on its face");
    // Entering goes against the outward normal, leaving along it.
    let along = ray.dir.dot(hit.normal);
    assert!(
        if outward { along > 0.0 } else { along < 0.0 },
        "{ray:?}: {hit:?}"
    );
    let scale = 1.0 + hit.t;
    assert!(
        (hit.point - ray.at(hit.t)).length() < 1e-5 * scale,
        "{ray:?}: {hit:?} vs {:?}",
        ray.at(hit.t)
    );
}

#[test]
fn entry_through_each_face_along_its_axis() {
    let b = unit_box();
    for a in 0..3 {
        for max_side in [false, true] {
            for negative_zeros in [false, true] {
                let mut origin = Vec3::new(0.25, -0.5, 1.5);
                origin[a] = if max_side {
                    b.max[a] + 3.0
                } else {
                    b.min[a] - 3.0
                };
                let zero = if negative_zeros { -0.0 } else { 0.0 };
                let mut dir = Vec3::splat(zero);
                dir[a] = if max_side { -1.0 } else { 1.0 };
                let ray = Ray::new(origin, dir);
                let hit = b.entry(&ray).expect("an axis ray aimed at a face enters");
                assert_eq!(hit.t, 3.0);
                let mut point = origin;
                point[a] = if max_side { b.max[a] } else { b.min[a] };
                assert_eq!(hit.point, point);
                assert_eq!(hit.normal, if max_side { axis(a) } else { -axis(a) });
                // And it leaves through the opposite face.
                let exit = b.exit(&Ray::new(hit.point, dir));
                assert_eq!(exit.t, b.extent()[a]);
                assert_eq!(exit.normal, -hit.normal);
            }
        }
    }
}

#[test]
fn entry_agrees_with_f64_slab_test() {
    let b = unit_box();
    let mut rng = TestRng::new(21);
    let (mut hits, mut misses) = (0, 0);
    for i in 0..20_000 {
        let origin = loop {
            let p = Vec3::new(
                rng.range(-6.0, 6.0) as f32,
                rng.range(-6.0, 6.0) as f32,
                rng.range(-6.0, 6.0) as f32,
            );
            if !b.contains(p) {
                break p;
            }
        };
        // Half the rays aim at an interior point, half go anywhere.
        let dir = if i % 2 == 0 {
            let target = Vec3::new(
                rng.range(-1.0, 1.0) as f32,
                rng.range(-2.0, 2.0) as f32,
                rng.range(0.0, 4.0) as f32,
            );
            (target - origin).normalize()
        } else {
            rng.unit_vector()
        };
        let ray = Ray::new(origin, dir);
        let reference = slabs(&b, &ray);
        let got = b.entry(&ray);
        // Only rays that clear every edge by 1e-4 in distance are compared: closer ones are within
        // f32 rounding of touching.
        match reference {
            Some((t_enter, t_leave, enter_axis, _))
                if t_enter >= 0.0 && t_leave - t_enter > 1e-4 =>
            {
                let hit = got.unwrap_or_else(|| panic!("{ray:?} should enter at {t_enter}"));
                assert!(
                    (hit.t as f64 - t_enter).abs() < 1e-5 * (1.0 + t_enter),
                    "{ray:?}: {hit:?} vs {t_enter}"
                );
                check_on_face(&b, &ray, &hit, false);
                assert_eq!(hit.normal.abs().max_position(), enter_axis);
                hits += 1;
            }
            Some((t_enter, t_leave, _, _)) if t_leave - t_enter < -1e-4 || t_leave < -1e-4 => {
                assert!(got.is_none(), "{ray:?} should miss: {got:?}");
                misses += 1;
            }
            None => {
                assert!(got.is_none(), "{ray:?} should miss: {got:?}");
                misses += 1;
            }
            _ => {}
        }
    }
    assert!(
        hits > 5_000 && misses > 5_000,
        "{hits} hits, {misses} misses"
    );
}

#[test]
fn entry_through_an_edge_and_a_corner() {
    let b = unit_box();
    // Through the edge x = -1, y = -2 into the interior.
    let ray = Ray::new(
        Vec3::new(-2.0, -3.0, 1.0),
        Vec3::new(1.0, 1.0, 0.0).normalize(),
    );
    let hit = b.entry(&ray).expect("enters through an edge");
    assert!(
        (hit.point - Vec3::new(-1.0, -2.0, 1.0)).length() < 1e-6,
        "{hit:?}"
    );
    assert!(hit.normal == -Vec3::X || hit.normal == -Vec3::Y, "{hit:?}");
    assert!((hit.t - 2f32.sqrt()).abs() < 1e-6);
    check_on_face(&b, &ray, &hit, false);
    // Through the corner (-1, -2, 0).
    let ray = Ray::new(Vec3::new(-2.0, -3.0, -1.0), Vec3::ONE.normalize());
    let hit = b.entry(&ray).expect("enters through a corner");
    assert!(
        (hit.point - Vec3::new(-1.0, -2.0, 0.0)).length() < 1e-6,
        "{hit:?}"
    );
    assert!((hit.t - 3f32.sqrt()).abs() < 1e-6);
    check_on_face(&b, &ray, &hit, false);
    // Through the opposite corner (1, 2, 4) from beyond it.
    let ray = Ray::new(Vec3::new(2.0, 3.0, 5.0), -Vec3::ONE.normalize());
    let hit = b.entry(&ray).expect("enters through a corner");
    assert!((hit.point - b.max).length() < 1e-6, "{hit:?}");
    check_on_face(&b, &ray, &hit, false);
}

#[test]
fn grazing_along_a_face_is_the_same_on_every_face() {
    // A ray in the plane of a face, crossing the box's extent along another axis, touches the closed
    // box along a segment of that face. The slab it lies in puts no constraint on it (the box is
    // closed), so it enters at the edge where it meets the box, whichever face it grazes and
    // whatever the sign of its zero components: the box's mirror symmetries must not change that.
    let b = unit_box();
    for a in 0..3 {
        for max_side in [false, true] {
            for travel in (0..3).filter(|&t| t != a) {
                for negative_zeros in [false, true] {
                    let third = 3 - a - travel;
                    let mut origin = Vec3::ZERO;
                    origin[a] = if max_side { b.max[a] } else { b.min[a] };
                    origin[travel] = b.min[travel] - 3.0;
                    origin[third] = 0.5 * (b.min[third] + b.max[third]);
                    let zero = if negative_zeros { -0.0 } else { 0.0 };
                    let mut dir = Vec3::splat(zero);
                    dir[travel] = 1.0;
                    let ray = Ray::new(origin, dir);
                    let hit = b.entry(&ray).unwrap_or_else(|| {
                        panic!("face {a} (max {max_side}), along {travel}, -0 {negative_zeros}: no hit")
                    });
                    assert_eq!(hit.t, 3.0, "{ray:?}: {hit:?}");
                    assert_eq!(hit.normal, -axis(travel), "{ray:?}: {hit:?}");
                    assert_eq!(hit.point[a], origin[a]);
                    assert_eq!(hit.point[travel], b.min[travel]);
                    // The same ray just beside the face misses.
                    let mut beside = origin;
                    beside[a] += if max_side { 1e-3 } else { -1e-3 };
                    assert!(b.entry(&Ray::new(beside, dir)).is_none(), "{beside:?}");
                }
            }
        }
    }
}

#[test]
fn exit_agrees_with_f64_slab_test() {
    let b = unit_box();
    let mut rng = TestRng::new(22);
    for _ in 0..20_000 {
        let origin = Vec3::new(
            rng.range(-1.0, 1.0) as f32,
            rng.range(-2.0, 2.0) as f32,
            rng.range(0.0, 4.0) as f32,
        );
        let ray = Ray::new(origin, rng.unit_vector());
        let (_, t_leave, _, leave_axis) = slabs(&b, &ray).unwrap();
        let hit = b.exit(&ray);
        assert!(
            (hit.t as f64 - t_leave).abs() < 1e-5 * (1.0 + t_leave),
            "{ray:?}: {hit:?} vs {t_leave}"
        );
        check_on_face(&b, &ray, &hit, true);
        let d = ray.dir.abs();
        // Away from ties between faces, the face is the reference's.
        let mut others: Vec<f64> = (0..3)
            .filter(|&i| i != leave_axis && d[i] > 0.0)
            .map(|i| {
                let plane = if ray.dir[i] > 0.0 { b.max[i] } else { b.min[i] };
                (plane - ray.origin[i]) as f64 / ray.dir[i] as f64
            })
            .collect();
        others.push(f64::INFINITY);
        let second = others.iter().cloned().fold(f64::INFINITY, f64::min);
        if second - t_leave > 1e-4 {
            assert_eq!(
                hit.normal.abs().max_position(),
                leave_axis,
                "{ray:?}: {hit:?}"
            );
        }
    }
}

/// The free flight's distance (`exit_distance`) is `exit(ray).t` bit for bit (paths take the
/// same branches whichever they use): inside, from faces, edges and corners, pointing out, and
/// along axes with signed zeros.
#[test]
fn exit_distance_is_the_exit_hits_distance() {
    let b = unit_box();
    let mut rng = TestRng::new(24);
    let mut rays = Vec::new();
    for _ in 0..20_000 {
        let origin = Vec3::new(
            rng.range(-1.0, 1.0) as f32,
            rng.range(-2.0, 2.0) as f32,
            rng.range(0.0, 4.0) as f32,
        );
        rays.push(Ray::new(origin, rng.unit_vector()));
        let (_, _, p) = random_face_point(&b, &mut rng);
        rays.push(Ray::new(p, rng.unit_vector()));
    }
    let corners = [
        b.min,
        b.max,
        Vec3::new(-1.0, -2.0, 2.0),
        Vec3::new(0.0, 0.0, 2.0),
    ];
    for origin in corners {
        for a in 0..3 {
            for sign in [1.0f32, -1.0] {
                for z in [0.0f32, -0.0] {
                    let mut dir = Vec3::splat(z);
                    dir[a] = sign;
                    rays.push(Ray::new(origin, dir));
                }
            }
        }
    }
    for ray in &rays {
        assert_eq!(
            b.exit_distance(ray).to_bits(),
            b.exit(ray).t.to_bits(),
            "{ray:?}"
        );
    }
}

#[test]
fn exit_from_the_surface() {
    let b = unit_box();
    // From a point on a face, pointing in: leaves through the opposite face.
    let ray = Ray::new(Vec3::new(-1.0, 0.3, 1.0), Vec3::X);
    let hit = b.exit(&ray);
    assert_eq!((hit.t, hit.normal), (2.0, Vec3::X));
    assert_eq!(hit.point, Vec3::new(1.0, 0.3, 1.0));
    // From a corner, pointing in along the diagonal: x is the nearest far plane (2 sqrt 3).
    let ray = Ray::new(b.min, Vec3::ONE.normalize());
    let hit = b.exit(&ray);
    check_on_face(&b, &ray, &hit, true);
    assert_eq!(hit.normal, Vec3::X);
    assert!((hit.t - 2.0 * 3f32.sqrt()).abs() < 1e-5);
    // From the opposite corner, pointing in.
    let ray = Ray::new(b.max, -Vec3::ONE.normalize());
    let hit = b.exit(&ray);
    check_on_face(&b, &ray, &hit, true);
    assert_eq!(hit.normal, -Vec3::X);
    // From a face, pointing out: zero distance, that face's normal, never negative.
    let mut rng = TestRng::new(23);
    for _ in 0..1000 {
        let (a, max_side, p) = random_face_point(&b, &mut rng);
        let n = if max_side { axis(a) } else { -axis(a) };
        let mut dir = rng.unit_vector();
        if dir.dot(n) < 0.0 {
            dir -= 2.0 * dir.dot(n) * n;
        }
        if dir.dot(n) < 1e-3 {
            continue;
        }
        let hit = b.exit(&Ray::new(p, dir));
        assert_eq!(hit.t, 0.0, "{p:?} {dir:?}: {hit:?}");
        assert_eq!(hit.normal, n);
        assert_eq!(hit.point, p);
    }
}

fn random_face_point(b: &Aabb, rng: &mut TestRng) -> (usize, bool, Vec3) {
    let a = (rng.next_u64() % 3) as usize;
    let max_side = rng.next_u64() & 1 == 1;
    let mut p = Vec3::ZERO;
    for i in 0..3 {
        p[i] = rng.range(b.min[i] as f64, b.max[i] as f64) as f32;
    }
    p[a] = if max_side { b.max[a] } else { b.min[a] };
    (a, max_side, p)
}

#[test]
fn surface_points_pointing_away_do_not_enter() {
    let b = unit_box();
    let mut rng = TestRng::new(24);
    // Faces: any direction with a positive component along the outward normal.
    for _ in 0..10_000 {
        let (a, max_side, p) = random_face_point(&b, &mut rng);
        let n = if max_side { axis(a) } else { -axis(a) };
        let mut dir = rng.unit_vector();
        if dir.dot(n) < 0.0 {
            dir -= 2.0 * dir.dot(n) * n;
        }
        if dir.dot(n) <= 0.0 {
            continue;
        }
        assert!(b.entry(&Ray::new(p, dir)).is_none(), "{p:?} {dir:?}");
    }
    // Edges and corners: any direction that leaves the closed box at once, i.e. that points outward
    // through at least one of the faces meeting there. Such a ray only touches the box at its origin.
    for _ in 0..10_000 {
        let mut p = Vec3::ZERO;
        let mut sides = [0i8; 3];
        let corner = rng.next_u64() & 1 == 0;
        let free = (rng.next_u64() % 3) as usize;
        for i in 0..3 {
            if !corner && i == free {
                p[i] = rng.range(b.min[i] as f64, b.max[i] as f64) as f32;
            } else {
                sides[i] = if rng.next_u64() & 1 == 0 { -1 } else { 1 };
                p[i] = if sides[i] > 0 { b.max[i] } else { b.min[i] };
            }
        }
        let dir = rng.unit_vector();
        let leaves = (0..3).any(|i| sides[i] != 0 && dir[i] * sides[i] as f32 > 0.0);
        if !leaves {
            continue;
        }
        assert!(
            b.entry(&Ray::new(p, dir)).is_none(),
            "{p:?} {dir:?}: {:?}",
            b.entry(&Ray::new(p, dir))
        );
    }
}

#[test]
fn axis_parallel_rays_with_signed_zeros_stay_finite() {
    let b = unit_box();
    let zeros = [0.0f32, -0.0];
    let origins = [
        Vec3::new(0.0, 0.0, 2.0),   // inside
        Vec3::new(-1.0, 0.0, 2.0),  // on a face
        Vec3::new(-1.0, -2.0, 2.0), // on an edge
        Vec3::new(-1.0, -2.0, 0.0), // on a corner
        Vec3::new(-3.0, 0.0, 2.0),  // outside
        Vec3::new(-3.0, -2.0, 0.0), // outside, in the planes of two faces
    ];
    for &origin in &origins {
        for a in 0..3 {
            for sign in [1.0f32, -1.0] {
                for &z1 in &zeros {
                    for &z2 in &zeros {
                        let mut dir = Vec3::new(z1, z2, z1);
                        dir[a] = sign;
                        let ray = Ray::new(origin, dir);
                        if let Some(hit) = b.entry(&ray) {
                            check_on_face(&b, &ray, &hit, false);
                        }
                        if b.contains(origin) {
                            let hit = b.exit(&ray);
                            assert!(hit.t.is_finite() && hit.t >= 0.0, "{ray:?}: {hit:?}");
                            assert_finite_vec(hit.point, "exit point");
                            assert!(b.contains(hit.point));
                            assert_eq!(hit.normal, sign * axis(a), "{ray:?}: {hit:?}");
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn entry_then_exit_is_the_chord() {
    let b = unit_box();
    let mut rng = TestRng::new(25);
    for _ in 0..10_000 {
        let origin = Vec3::new(
            rng.range(-8.0, 8.0) as f32,
            rng.range(-8.0, 8.0) as f32,
            rng.range(-8.0, 8.0) as f32,
        );
        if b.contains(origin) {
            continue;
        }
        let ray = Ray::new(origin, rng.unit_vector());
        let Some((t_enter, t_leave, _, _)) = slabs(&b, &ray) else {
            continue;
        };
        if t_enter < 0.0 || t_leave - t_enter < 1e-3 {
            continue;
        }
        let hit = b.entry(&ray).expect("enters");
        let exit = b.exit(&Ray::new(hit.point, ray.dir));
        let chord = t_leave - t_enter;
        assert!(
            (exit.t as f64 - chord).abs() < 2e-5 * (1.0 + t_leave),
            "{ray:?}: {} vs {chord}",
            exit.t
        );
        check_on_face(&b, &Ray::new(hit.point, ray.dir), &exit, true);
    }
}

fn check_frame(n: Vec3) {
    let f = Frame::from_z(n);
    let tol = 1e-6;
    for (name, v) in [("x", f.x), ("y", f.y), ("z", f.z)] {
        assert!(v.is_finite(), "n {n:?}: {name} = {v:?}");
        assert!(
            (v.length() - 1.0).abs() < tol,
            "n {n:?}: |{name}| = {}",
            v.length()
        );
    }
    assert_eq!(f.z, n);
    assert!(
        f.x.dot(f.y).abs() < tol && f.x.dot(f.z).abs() < tol && f.y.dot(f.z).abs() < tol,
        "n {n:?}: {f:?}"
    );
    // Right-handed: x cross y = z.
    assert!(
        (f.x.cross(f.y) - f.z).length() < tol,
        "n {n:?}: {f:?} is left-handed"
    );
    let v = Vec3::new(0.3, -0.7, 0.2);
    assert!((f.to_world(f.to_local(v)) - v).length() < tol);
    assert!((f.to_local(n) - Vec3::Z).length() < tol);
}

#[test]
fn frame_is_orthonormal_and_right_handed() {
    for n in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
        check_frame(n);
    }
    check_frame(Vec3::new(0.0, 0.0, -1.0));
    check_frame(Vec3::new(1.0, 0.0, -0.0));
    check_frame(Vec3::new(-0.0, -1.0, -0.0));
    check_frame(Vec3::new(1e-4, 0.0, -1.0).normalize());
    check_frame(Vec3::new(0.0, 1e-7, -1.0).normalize());
    check_frame(Vec3::new(1.0, 1e-7, 1e-7).normalize());
    let mut rng = TestRng::new(26);
    for _ in 0..100_000 {
        check_frame(rng.unit_vector());
    }
}
