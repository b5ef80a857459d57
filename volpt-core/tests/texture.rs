//! Grid lookups through textures (`TextureTrilinear`) as the CPU computes them: the texture unit's
//! filter (weights of 8 fractional bits, clamp addressing), half-precision texels rounded toward
//! zero, and the bounds delta tracking needs. The GPU's own lookups are compared with this filter
//! by `volpt selftest --backend cuda`.

use volpt_core::grid::{half_toward_zero, HALF_MAX};
use volpt_core::majorant::{build_majorants, MajorantGrid};
use volpt_core::rng::Rng;
use volpt_core::{Aabb, Grid, GridMapping, GridReads, TexelFormat, TextureTrilinear, Vec3};

fn bounds() -> Aabb {
    Aabb::new(Vec3::new(-1.0, 0.5, 2.0), Vec3::new(3.0, 1.5, 2.5))
}

fn random_grid(rng: &mut Rng, res: [u32; 3], channels: u32) -> Vec<f32> {
    (0..res.iter().product::<u32>() * channels)
        .map(|_| 4.0 * rng.next_f32())
        .collect()
}

/// A point inside `b` at fractions `u` of its extent.
fn at(b: Aabb, u: Vec3) -> Vec3 {
    b.min + b.extent() * u
}

#[test]
fn half_texels_are_the_largest_half_values_not_above_the_sample() {
    let mut rng = Rng::new(5, 0, 0);
    for _ in 0..100_000 {
        // Magnitudes from 2^-30 to 2^17, through half's subnormals and past its largest value.
        let x = (2.0f32).powf(47.0 * rng.next_f32() - 30.0);
        let h = half_toward_zero(x);
        assert!(h <= x, "{x}: {h} above");
        if x >= HALF_MAX {
            assert_eq!(h, HALF_MAX, "{x} saturates");
            continue;
        }
        // Representable in half, and the next half value up lies above x.
        let spacing = if h >= 1.0 / 16384.0 {
            assert_eq!(
                h.to_bits() & 0x1fff,
                0,
                "{x}: {h} has more than 10 fraction bits"
            );
            f32::from_bits(h.to_bits() + 0x2000) - h
        } else {
            let steps = h * 16_777_216.0;
            assert_eq!(steps, steps.trunc(), "{x}: {h} is not a multiple of 2^-24");
            1.0 / 16_777_216.0
        };
        assert!(
            h + spacing > x,
            "{x}: {h} is not the largest half value below"
        );
    }
    assert_eq!(half_toward_zero(0.0), 0.0);
    assert_eq!(half_toward_zero(1.0), 1.0);
    assert_eq!(TexelFormat::F32.texel(0.1), 0.1);
    assert!(TexelFormat::F16.texel(0.1) < 0.1);
}

/// Two samples along x, 0 and 1: the filter's value between them is its weight, a multiple of
/// 1/256 rounded to nearest; at and beyond the samples it is theirs (clamp addressing).
#[test]
fn filter_weights_are_rounded_to_eight_fraction_bits() {
    let b = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0));
    let res = [2, 1, 1];
    let data = [0.0, 1.0];
    // Cell-centred: sample i at x = i + 0.5, so index-space q = x - 0.5.
    let grid = Grid::<1>::new(&data, res, GridMapping::cell_centred(b, res));
    for k in 0..=1000 {
        let q = k as f32 / 1000.0;
        let got = grid.lookup_texture_filter(Vec3::new(q + 0.5, 0.5, 0.5))[0];
        let expected = (q * 256.0).round() / 256.0;
        assert_eq!(got, expected, "q = {q}");
    }
    assert_eq!(grid.lookup_texture_filter(Vec3::new(0.1, 0.5, 0.5))[0], 0.0);
    assert_eq!(grid.lookup_texture_filter(Vec3::new(1.9, 0.5, 0.5))[0], 1.0);
    assert_eq!(
        grid.lookup_texture_filter(Vec3::new(2.1, 0.5, 0.5))[0],
        0.0,
        "outside"
    );
}

/// Within three weight steps (one per axis) of exact trilinear interpolation everywhere, for
/// both sample conventions and both channel counts: a filter off by half a texel, or reading the
/// wrong channel, is off by a good part of the samples' range.
#[test]
fn the_filter_is_within_a_weight_step_per_axis_of_trilinear() {
    let mut rng = Rng::new(6, 0, 0);
    for res in [[7, 5, 6], [1, 4, 3], [2, 2, 2]] {
        let mono = random_grid(&mut rng, res, 1);
        let rgb = random_grid(&mut rng, res, 3);
        for mapping in [
            GridMapping::cell_centred(bounds(), res),
            GridMapping::vertex_centred(bounds(), res),
        ] {
            let a = Grid::<1>::new(&mono, res, mapping);
            let c = Grid::<3>::new(&rgb, res, mapping);
            for _ in 0..20_000 {
                let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 1.1 - 0.05;
                let p = at(bounds(), u);
                let tolerance = 3.0 * 4.0 / 256.0 + 1e-5;
                let (t, e) = (TextureTrilinear::lookup(&a, p), a.lookup(p));
                assert!(
                    (t[0] - e[0]).abs() <= tolerance,
                    "{res:?} {p}: {t:?} vs {e:?}"
                );
                let (t, e) = (TextureTrilinear::lookup(&c, p), c.lookup(p));
                for ch in 0..3 {
                    assert!(
                        (t[ch] - e[ch]).abs() <= tolerance,
                        "{res:?} {p} channel {ch}: {t:?} vs {e:?}"
                    );
                }
            }
        }
    }
}

/// The majorants built from the samples bound every filtered lookup of f32 and of half texels
/// (half texels are never above their samples).
#[test]
fn the_sample_majorants_bound_every_texture_lookup() {
    let mut rng = Rng::new(7, 0, 0);
    let res = [9, 7, 8];
    let mut density = random_grid(&mut rng, res, 1);
    // A spike and some empty samples, where a loose filter would show most.
    density[100] = 60_000.0;
    for d in density.iter_mut().step_by(7) {
        *d = 0.0;
    }
    let cells = [4, 3, 5];
    for texel in [TexelFormat::F32, TexelFormat::F16] {
        let grid = Grid::<1>::new(&density, res, GridMapping::vertex_centred(bounds(), res))
            .with_texel(texel);
        let scale = 1.7;
        let mut data = vec![0.0; 60];
        build_majorants(&grid, scale, bounds(), cells, &mut data);
        let majorants = MajorantGrid::new(&data, cells, bounds());
        for _ in 0..200_000 {
            let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let p = at(bounds(), u);
            let sigma = scale * TextureTrilinear::lookup(&grid, p)[0];
            let bound = majorants.at_point(p);
            assert!(sigma <= bound, "{texel:?} {p}: {sigma} above {bound}");
        }
    }
}
