//! The stochastic trilinear lookup (`GridLookup::Stochastic`) is an unbiased estimate of the
//! trilinear one: exactly, corner by corner (the probability of each corner against its
//! trilinear weight, by enumerating every value of the random bits per axis), and statistically,
//! as the trackers draw it (the mean of many lookups with the renderer's own random numbers against
//! the trilinear value, a chi-square over many points that a planted 1% bias fails).

mod common;

use common::*;
use volpt_core::grid::stochastic_corner;
use volpt_core::{Aabb, Grid, GridLookup, GridMapping, Rng, Vec3};

/// Random bits per axis of the lookup (`STOCHASTIC_BITS` in `grid.rs`).
const AXIS_BITS: u32 = 13;
const STEPS: u32 = 1 << AXIS_BITS;

fn bounds() -> Aabb {
    Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.5, 4.5))
}

/// The trilinear weight of the upper sample along one axis, as `trilinear` computes it.
fn fraction(q: f32, max_index: f32) -> f32 {
    q - q.floor().min((max_index - 1.0).max(0.0))
}

/// Along each axis, the upper sample is chosen with probability equal to its trilinear weight,
/// to within the 2^-13 resolution of the uniform (every 13-bit value enumerated; the other axes'
/// bits do not change the axis's choice), and only the two samples around `q` are ever chosen.
#[test]
fn each_axis_chooses_the_upper_sample_with_its_trilinear_weight() {
    let mut rng = TestRng::new(7);
    for case in 0..300 {
        let res = [
            1 + (rng.next_u64() % 9) as u32,
            1 + (rng.next_u64() % 40) as u32,
            2 + (rng.next_u64() % 300) as u32,
        ];
        let max_index = Vec3::new(
            (res[0] - 1) as f32,
            (res[1] - 1) as f32,
            (res[2] - 1) as f32,
        );
        // Interior points, and the edges and samples themselves, where a weight is 0 or 1.
        let mut q = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * max_index;
        if case % 5 == 0 {
            q = q.round();
        }
        let other = rng.next_u64();
        for axis in 0..3 {
            let shift = AXIS_BITS * axis as u32;
            let lower = q[axis].floor().min((max_index[axis] - 1.0).max(0.0)) as u32;
            let mut upper = 0u32;
            for k in 0..u64::from(STEPS) {
                let mask = u64::from(STEPS - 1) << shift;
                let bits = (other & !mask) | (k << shift);
                let corner = stochastic_corner(q, max_index, res, bits)[axis];
                assert!(
                    corner == lower || corner == (lower + 1).min(res[axis] - 1),
                    "case {case} axis {axis}: corner {corner} around {q}"
                );
                upper += u32::from(corner != lower);
            }
            let f = fraction(q[axis], max_index[axis]);
            let p = f64::from(upper) / f64::from(STEPS);
            assert!(
                (p - f64::from(f)).abs() <= 0.5 / f64::from(STEPS) + 1e-7,
                "case {case} axis {axis}: upper chosen with probability {p}, weight {f} (q {q})"
            );
        }
    }
}

/// A random grid of `C` channels over `bounds()`, values in [0, 1).
fn random_grid<const C: usize>(rng: &mut TestRng, res: [u32; 3]) -> Vec<f32> {
    (0..res.iter().product::<u32>() as usize * C)
        .map(|_| rng.f32())
        .collect()
}

/// The chi-square statistic, over `points`, of the mean of `n` lookups `estimate(p, bits)` (bits
/// drawn as the trackers draw them: a number of the renderer's stream) against `expected(p)`,
/// per channel: `sum z^2` with `z` the mean's distance from the expectation in standard errors.
/// Returns the statistic, its degrees of freedom and its p-value.
fn chi_square<const C: usize>(
    points: &[Vec3],
    n: u32,
    expected: impl Fn(Vec3) -> [f32; C],
    estimate: impl Fn(Vec3, u64) -> [f32; C],
) -> (f64, usize, f64) {
    let mut statistic = 0.0;
    let mut dof = 0;
    for (i, &p) in points.iter().enumerate() {
        let mut rng = Rng::new(11, i as u32, 0);
        let mut sum = [0.0f64; C];
        let mut sum2 = [0.0f64; C];
        for _ in 0..n {
            let v = estimate(p, rng.next_u64());
            for c in 0..C {
                sum[c] += f64::from(v[c]);
                sum2[c] += f64::from(v[c]) * f64::from(v[c]);
            }
        }
        let e = expected(p);
        for c in 0..C {
            let mean = sum[c] / f64::from(n);
            let var = (sum2[c] / f64::from(n) - mean * mean).max(0.0);
            if var <= 1e-12 {
                // All eight samples equal (or one sample read): the lookup must be exact.
                assert!(
                    (mean - f64::from(e[c])).abs() <= 1e-6,
                    "at {p}: constant lookup {mean} against {}",
                    e[c]
                );
                continue;
            }
            let z = (mean - f64::from(e[c])) / (var / f64::from(n)).sqrt();
            statistic += z * z;
            dof += 1;
        }
    }
    (statistic, dof, chi2_sf(statistic, dof))
}

/// Points spread over the grid's box, some outside it (zero), some beyond the outermost samples
/// (clamped).
fn points(rng: &mut TestRng, count: usize) -> Vec<Vec3> {
    let b = bounds();
    let margin = Vec3::splat(0.05);
    (0..count)
        .map(|_| {
            let u = Vec3::new(rng.f32(), rng.f32(), rng.f32());
            (b.min - margin) + u * (b.max - b.min + 2.0 * margin)
        })
        .collect()
}

const DRAWS: u32 = 20_000;

/// The mean of the stochastic lookup is the trilinear value, for density (1 channel) and albedo
/// (3 channels) grids of both conventions; the same test rejects the lookup scaled by 1.01.
#[test]
fn the_stochastic_lookup_is_an_unbiased_estimate_of_trilinear() {
    let mut rng = TestRng::new(3);
    let res = [7, 5, 9];
    let density = random_grid::<1>(&mut rng, res);
    let albedo = random_grid::<3>(&mut rng, res);
    for mapping in [
        GridMapping::vertex_centred(bounds(), res),
        GridMapping::cell_centred(bounds(), res),
    ] {
        let pts = points(&mut rng, 160);
        let d = Grid::<1>::new(&density, res, mapping);
        let ds = d.with_lookup(GridLookup::Stochastic);
        let (x2, dof, p) = chi_square(&pts, DRAWS, |p| d.lookup(p), |p, b| ds.lookup_random(p, b));
        eprintln!("density: chi2 {x2:.1} on {dof} dof, p {p:.3}");
        assert!(dof > 100, "too few points inside the grid: {dof}");
        assert!(p > ALPHA, "density: chi2 {x2} on {dof} dof, p {p}");

        let a = Grid::<3>::new(&albedo, res, mapping);
        let as_ = a.with_lookup(GridLookup::Stochastic);
        let (x2, dof, p) = chi_square(&pts, DRAWS, |p| a.lookup(p), |p, b| as_.lookup_random(p, b));
        eprintln!("albedo: chi2 {x2:.1} on {dof} dof, p {p:.3}");
        assert!(p > ALPHA, "albedo: chi2 {x2} on {dof} dof, p {p}");

        // The planted bias: the same test, a lookup 1% too large.
        let (x2, dof, p) = chi_square(
            &pts,
            DRAWS,
            |p| d.lookup(p),
            |p, b| [ds.lookup_random(p, b)[0] * 1.01],
        );
        eprintln!("density x 1.01: chi2 {x2:.1} on {dof} dof, p {p:.3e}");
        assert!(p < 1e-6, "a 1% bias passed: chi2 {x2} on {dof} dof, p {p}");
    }
}

/// Every stochastic lookup is one of the grid's samples (so a majorant of the samples bounds it),
/// the same in both layouts, and without random bits (`lookup`) the stochastic grid is trilinear
/// bit for bit, as are the other lookups with bits.
#[test]
fn stochastic_lookups_read_one_sample_and_leave_the_others_unchanged() {
    let mut rng = TestRng::new(5);
    let res = [6, 4, 5];
    let data = random_grid::<1>(&mut rng, res);
    let mapping = GridMapping::cell_centred(bounds(), res);
    let tri = Grid::<1>::new(&data, res, mapping);
    let sto = tri.with_lookup(GridLookup::Stochastic);
    let near = tri.with_lookup(GridLookup::Nearest);
    for p in points(&mut rng, 2000) {
        let bits = rng.next_u64();
        let v = sto.lookup_random(p, bits)[0];
        assert!(
            v == 0.0 && !bounds().contains(p) || data.contains(&v),
            "{v} at {p} is no sample"
        );
        assert_eq!(sto.lookup(p), tri.lookup(p));
        assert_eq!(tri.lookup_random(p, bits), tri.lookup(p));
        assert_eq!(near.lookup_random(p, bits), near.lookup(p));
    }
}
