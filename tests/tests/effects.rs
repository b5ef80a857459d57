//! Specialisation changes the code, not the image: a scene whose values make an effect trivial
//! (a constant grid, g = 0, an IOR ratio of 1, a constant environment) renders with a simpler
//! variant, and the fully general variant (`Effects::General`) gives a statistically equal image.
//!
//! The test: `K` independent renders of each, per-pixel means and variances over the renders; the
//! mean squared per-pixel z-score must be that of noise, and the whole image's mean must agree
//! within 4 standard errors. A 1% difference in albedo fails it (checked below).
//!
//! Every rule is also tested on both sides of its edge ([`edges`]): where its condition holds
//! exactly it fires, and just beside it (g = 0.01, an IOR ratio of 1.001, a grid with one voxel
//! different, ...) it must not, because there the simpler part would render a different image.

use volpt_render::factory::{Parts, Simplification};
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
        layout: volpt_scene::SampleLayout::Dense,
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
    let mut grey_rgb = cube_scene(
        12,
        12,
        homogeneous(1.0, 0.8, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    grey_rgb.medium.density = DensityDesc::Rgb([2.5; 3]);
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
        (
            "RGB extinction of equal channels",
            grey_rgb,
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

/// One rule of the factory at its edge: a scene where its condition holds exactly (the rule
/// fires, and the variant is `fired`), and scenes just beside the edge, each differing from an
/// exact case by as little as a description can, where no rule may fire and the variant must be
/// `general`.
struct Edge {
    rule: Simplification,
    fires: Vec<(String, SceneDescription)>,
    fired: &'static str,
    beside: Vec<(String, SceneDescription)>,
    general: &'static str,
}

/// A homogeneous cube (density 2, albedo 0.8, isotropic, index-matched) changed by `edit`.
fn scene_with(edit: impl FnOnce(&mut SceneDescription)) -> SceneDescription {
    let mut desc = cube_scene(
        4,
        4,
        homogeneous(2.0, 0.8, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    edit(&mut desc);
    desc
}

/// The next `f32` above `x` (positive `x`): the smallest change a scene file can make.
fn next_up(x: f32) -> f32 {
    f32::from_bits(x.to_bits() + 1)
}

/// Every [`Simplification`] at its edge. The values beside an edge are those a rule that fires
/// "near" its condition would take for exact: |g| = 0.01 and 1e-6; IOR ratios 1.001, 0.999 and
/// one ulp above 1; a depth limit or roulette with an IOR ratio of exactly 1; a grid one voxel of
/// which differs by 0.1% (one channel of one voxel for albedo), or that stops 1e-4 short of a
/// face of the medium's box (zero beyond it).
fn edges() -> Vec<Edge> {
    let hg = |g: f32| scene_with(|d| d.medium.phase = PhaseDesc::HenyeyGreenstein { g });
    let dielectric = |int_ior: f32, ext_ior: f32, max_depth: Option<u32>, rr_depth| {
        scene_with(|d| {
            d.boundary.bsdf = BsdfDesc::Dielectric { int_ior, ext_ior };
            d.integrator = IntegratorDesc {
                max_depth,
                rr_depth,
            };
        })
    };
    let density = |edit: &dyn Fn(&mut GridDesc)| {
        scene_with(|d| {
            let mut g = grid(&[1.0], [3, 2, 4]);
            edit(&mut g);
            d.medium.density = DensityDesc::Grid(g);
        })
    };
    let albedo = |edit: &dyn Fn(&mut GridDesc)| {
        scene_with(|d| {
            let mut g = grid(&[0.9, 0.7, 0.8], [2, 3, 2]);
            edit(&mut g);
            d.medium.albedo = AlbedoDesc::Grid(g);
        })
    };
    let short_of_the_box = |g: &mut GridDesc| g.bounds.max[1] = 0.4999;
    let rgb = |sigma: [f32; 3]| scene_with(|d| d.medium.density = DensityDesc::Rgb(sigma));
    vec![
        Edge {
            rule: Simplification::GreyExtinction,
            fires: vec![("RGB extinction 2, 2, 2".into(), rgb([2.0; 3]))],
            fired: "homogeneous/index_matched/isotropic/constant",
            beside: vec![
                ("blue 1 ulp denser".into(), rgb([2.0, 2.0, next_up(2.0)])),
                ("red 0.1% lighter".into(), rgb([1.998, 2.0, 2.0])),
            ],
            general: "chromatic/index_matched/isotropic/constant",
        },
        Edge {
            rule: Simplification::ZeroAsymmetry,
            fires: vec![("g = 0".into(), hg(0.0)), ("g = -0".into(), hg(-0.0))],
            fired: "homogeneous/index_matched/isotropic/constant",
            beside: [0.01, -0.01, 1e-6]
                .map(|g| (format!("g = {g}"), hg(g)))
                .into(),
            general: "homogeneous/index_matched/henyey_greenstein/constant",
        },
        Edge {
            rule: Simplification::UnitIorRatio,
            fires: vec![
                ("IOR 1.2 / 1.2".into(), dielectric(1.2, 1.2, None, None)),
                ("IOR 1 / 1".into(), dielectric(1.0, 1.0, None, None)),
            ],
            fired: "homogeneous/index_matched/isotropic/constant",
            beside: vec![
                (
                    "IOR ratio 1.001".into(),
                    dielectric(1.2012, 1.2, None, None),
                ),
                (
                    "IOR ratio 0.999".into(),
                    dielectric(1.1988, 1.2, None, None),
                ),
                (
                    "IOR ratio 1 + 1 ulp".into(),
                    dielectric(next_up(1.2), 1.2, None, None),
                ),
                (
                    "IOR ratio 1, max_depth 100".into(),
                    dielectric(1.2, 1.2, Some(100), None),
                ),
                (
                    "IOR ratio 1, roulette from depth 5".into(),
                    dielectric(1.2, 1.2, None, Some(5)),
                ),
            ],
            general: "homogeneous/smooth_dielectric/isotropic/constant",
        },
        Edge {
            rule: Simplification::ConstantDensityGrid,
            fires: vec![("constant density grid".into(), density(&|_| {}))],
            fired: "homogeneous/index_matched/isotropic/constant",
            beside: vec![
                (
                    "last voxel 0.1% denser".into(),
                    density(&|g| *g.data.last_mut().unwrap() = 1.001),
                ),
                (
                    "first voxel 0.1% lighter".into(),
                    density(&|g| g.data[0] = 0.999),
                ),
                (
                    "constant grid 1e-4 short of the box".into(),
                    density(&short_of_the_box),
                ),
            ],
            general:
                "grid_density__constant_albedo__dense_trilinear/index_matched/isotropic/constant",
        },
        Edge {
            rule: Simplification::ConstantAlbedoGrid,
            fires: vec![("constant albedo grid".into(), albedo(&|_| {}))],
            fired: "homogeneous/index_matched/isotropic/constant",
            beside: vec![
                (
                    "green of one voxel 0.1% higher".into(),
                    albedo(&|g| g.data[3 * 5 + 1] = 0.7007),
                ),
                (
                    "constant albedo grid 1e-4 short of the box".into(),
                    albedo(&short_of_the_box),
                ),
            ],
            general: "grid_density__grid_albedo__dense_trilinear/index_matched/isotropic/constant",
        },
    ]
}

/// Each rule fires where its condition holds exactly, and no rule fires just beside it: there the
/// variant keeps the general part, which renders what the description says. Every case is checked
/// and every wrong one reported, so that a rule that fires too widely is named with all its cases.
#[test]
fn every_specialisation_rule_fires_at_its_edge_and_not_beside_it() {
    let mut wrong = Vec::new();
    for edge in edges() {
        let cases = edge.fires.iter().map(|(name, desc)| (name, desc, true));
        let beside = edge.beside.iter().map(|(name, desc)| (name, desc, false));
        for (name, desc, fires) in cases.chain(beside) {
            let parts = Parts::of(desc, Effects::Specialised);
            let (rules, variant) = if fires {
                (vec![edge.rule], edge.fired)
            } else {
                (vec![], edge.general)
            };
            if parts.simplifications != rules || parts.variant().to_string() != variant {
                wrong.push(format!(
                    "{:?}, {name}: rules {:?} and variant {}, expected {rules:?} and {variant}",
                    edge.rule,
                    parts.simplifications,
                    parts.variant()
                ));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
