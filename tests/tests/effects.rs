//! Specialisation changes the code, not the image: a scene whose values make an effect trivial
//! (a constant grid, g = 0, an IOR ratio of 1, a constant environment) renders with a simpler
//! variant, and the fully general variant (`Effects::General`) gives a statistically equal image.
//!
//! The test: `K` independent renders of each, per-pixel means and variances over the renders; the
//! mean squared per-pixel z-score must be that of noise, and the whole image's mean must agree
//! within 4 standard errors. A 1% difference in albedo fails it (checked below).

use volpt_render::factory::Parts;
use volpt_render::{
    with_scene_as, Effects, Image, RenderOptions, RenderScene, SceneVisitor, Variant,
};
use volpt_scene::description::*;
use volpt_tests::{cube_scene, homogeneous};

const K: u32 = 8;

struct Cpu(RenderOptions);

impl SceneVisitor for Cpu {
    type Output = Image;
    fn visit<S: RenderScene>(self, scene: &S) -> Image {
        volpt_render::render(scene, &self.0, &|_, _| {})
            .expect("render")
            .0
    }
}

/// Per-pixel (mean, variance of the mean) of the first channel over `K` seeds.
fn moments(desc: &SceneDescription, effects: Effects, seed_base: u32) -> Vec<(f64, f64)> {
    let images: Vec<Image> = (0..K)
        .map(|k| {
            let options = RenderOptions {
                spp: 64,
                seed: seed_base + k,
                threads: None,
            };
            with_scene_as(
                desc,
                volpt_render::path_settings(desc),
                effects,
                Cpu(options),
            )
        })
        .collect();
    (0..images[0].pixels.len())
        .map(|i| {
            let values: Vec<f64> = images.iter().map(|im| im.pixels[i][0] as f64).collect();
            let mean = values.iter().sum::<f64>() / K as f64;
            let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (K - 1) as f64;
            (mean, var / K as f64)
        })
        .collect()
}

/// Mean squared per-pixel z-score and the whole image's z-score of `a` against `b`.
fn compare(a: &[(f64, f64)], b: &[(f64, f64)]) -> (f64, f64) {
    let mut z2 = 0.0;
    let mut n = 0;
    let (mut diff, mut var) = (0.0, 0.0);
    for (&(ma, va), &(mb, vb)) in a.iter().zip(b) {
        diff += ma - mb;
        var += va + vb;
        if va + vb > 0.0 {
            z2 += (ma - mb).powi(2) / (va + vb);
            n += 1;
        }
    }
    (z2 / n.max(1) as f64, diff / var.sqrt().max(1e-30))
}

fn grid(value: &[f32], res: [u32; 3]) -> GridDesc {
    let n = (res[0] * res[1] * res[2]) as usize;
    GridDesc {
        resolution: res,
        channels: value.len() as u32,
        bounds: Bounds {
            min: [-0.5; 3],
            max: [0.5; 3],
        },
        convention: GridConvention::Cell,
        data: value
            .iter()
            .copied()
            .cycle()
            .take(n * value.len())
            .collect(),
    }
}

/// Scenes that exercise each specialisation, and the part the specialised variant must pick.
fn scenes() -> Vec<(&'static str, SceneDescription, &'static str)> {
    let rough = BsdfDesc::RoughDielectric {
        alpha: 0.2,
        int_ior: 1.3,
        ext_ior: 1.0,
    };
    let hg0 = PhaseDesc::HenyeyGreenstein { g: 0.0 };
    let mut constant_grids = cube_scene(12, 12, homogeneous(1.0, 0.8, hg0), rough, 1.0);
    constant_grids.medium.density = DensityDesc::Grid(grid(&[1.0], [3, 2, 4]));
    constant_grids.medium.scale = 4.0;
    constant_grids.medium.albedo = AlbedoDesc::Grid(grid(&[0.9, 0.7, 0.8], [2, 2, 2]));
    let mut unit_ior = cube_scene(
        12,
        12,
        homogeneous(3.0, 0.9, PhaseDesc::Isotropic),
        BsdfDesc::Dielectric {
            int_ior: 1.2,
            ext_ior: 1.2,
        },
        1.0,
    );
    unit_ior.integrator.rr_depth = None;
    vec![
        (
            "constant grids, g = 0",
            constant_grids,
            "homogeneous/rough_dielectric/isotropic/constant",
        ),
        (
            "IOR ratio 1",
            unit_ior,
            "homogeneous/index_matched/isotropic/constant",
        ),
    ]
}

#[test]
fn specialised_and_general_variants_render_the_same_image() {
    for (name, desc, expected) in scenes() {
        let parts = Parts::of(&desc, Effects::Specialised);
        assert_eq!(parts.variant().to_string(), expected, "{name}");
        assert!(!parts.simplifications.is_empty(), "{name}: a rule fired");
        let general = Parts::of(&desc, Effects::General).variant();
        assert_ne!(general, Variant::of(&desc), "{name}");
        let specialised = moments(&desc, Effects::Specialised, 100);
        let general = moments(&desc, Effects::General, 200);
        let (z2, z_image) = compare(&specialised, &general);
        // For K = 8 renders a squared z-score of noise has mean ~1.3 (a t-like ratio).
        assert!(z2 < 2.5, "{name}: mean squared per-pixel z {z2}");
        assert!(z_image.abs() < 4.0, "{name}: image z {z_image}");
    }
}

/// The test sees a 1% change of albedo: it is not too weak to catch a biased variant.
#[test]
fn a_one_percent_albedo_change_is_detected() {
    let (_, desc, _) = scenes().swap_remove(1);
    let mut darker = desc.clone();
    darker.medium.albedo = AlbedoDesc::Constant([0.9 * 0.99; 3]);
    let a = moments(&desc, Effects::General, 100);
    let b = moments(&darker, Effects::General, 200);
    let (_, z_image) = compare(&a, &b);
    assert!(z_image.abs() >= 4.0, "image z {z_image}");
}
