//! The factory's default majorants (`volpt_render::factory::default_majorants`): a grid where its
//! cells cut the tracking work per real collision at least `GRID_MARGIN`-fold (a dense plume in an
//! empty box, like smoke), the global majorant where they do not (a gently varying density, like
//! bucky's, or one value everywhere, like ad's), and the scene's integrator settings use the choice.

use volpt_core::majorant::MajorantGrid;
use volpt_core::{Aabb, Estimator, PathSettings, Rng, Vec3};
use volpt_render::factory::{
    default_majorants, tracking_cost, MajorantChoice, MajorantRule, TrackingCost,
};
use volpt_render::path_settings;
use volpt_scene::description::*;
use volpt_tests::{cube_scene, homogeneous};

const RES: u32 = 24;

fn grid_scene(density: impl Fn(f32, f32, f32) -> f32) -> SceneDescription {
    let mut data = Vec::new();
    for z in 0..RES {
        for y in 0..RES {
            for x in 0..RES {
                let c = |i: u32| (i as f32 + 0.5) / RES as f32 - 0.5;
                data.push(density(c(x), c(y), c(z)));
            }
        }
    }
    let medium = MediumDesc {
        density: DensityDesc::Grid(GridDesc {
            layout: volpt_scene::SampleLayout::Dense,
            resolution: [RES; 3],
            channels: 1,
            bounds: Bounds {
                min: [-0.5; 3],
                max: [0.5; 3],
            },
            convention: GridConvention::Cell,
            data,
        }),
        scale: 50.0,
        ..homogeneous(1.0, 0.9, PhaseDesc::Isotropic)
    };
    cube_scene(32, 32, medium, BsdfDesc::Null, 1.0)
}

fn cost(desc: &SceneDescription, majorant_resolution: u32) -> TrackingCost {
    let settings = PathSettings {
        majorant_resolution,
        estimator: Estimator::PathTracing,
        ..PathSettings::default()
    };
    tracking_cost(desc, settings).expect("camera rays see extinction")
}

/// A dense ball of radius 0.15 in an otherwise empty box: the global majorant wastes almost every
/// tentative collision, a grid very few; the rule picks the cheapest grid and says so, its costs
/// are those of `tracking_cost`, and `path_settings` renders with it.
#[test]
fn a_plume_in_an_empty_box_gets_a_grid() {
    let desc = grid_scene(|x, y, z| {
        if x * x + y * y + z * z < 0.15 * 0.15 {
            1.0
        } else {
            0.0
        }
    });
    let choice = default_majorants(&desc);
    assert_eq!(choice.rule, MajorantRule::GridSavesEnough, "{choice:?}");
    assert!(MajorantChoice::RESOLUTIONS.contains(&choice.resolution));
    let global = cost(&desc, 1);
    assert_eq!(global.crossings_ratio, 0.0);
    assert!(!global.grid);
    assert_eq!(global.majorant_ratio, global.global_ratio);
    let chosen = cost(&desc, choice.resolution);
    assert!(chosen.grid && chosen.crossings_ratio > 0.0);
    assert!(chosen.per_collision() * MajorantChoice::GRID_MARGIN <= global.per_collision());
    assert_eq!(choice.costs[0], (1, global.per_collision()));
    let least = choice
        .costs
        .iter()
        .map(|c| c.1)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(least, chosen.per_collision(), "{choice:?}");
    assert_eq!(choice.costs.len(), 1 + MajorantChoice::RESOLUTIONS.len());
    assert_eq!(path_settings(&desc).majorant_resolution, choice.resolution);
}

/// Densities within 20% of each other everywhere: a grid's cells save little tracking and cost
/// their crossings, so the global majorant stays.
#[test]
fn a_gently_varying_density_keeps_the_global_majorant() {
    let mut rng = Rng::new(4, 0, 0);
    let noise: Vec<f32> = (0..RES * RES * RES).map(|_| rng.next_f32()).collect();
    let index = |x: f32| (((x + 0.5) * RES as f32) as u32).min(RES - 1);
    let desc = grid_scene(|x, y, z| {
        0.8 + 0.2 * noise[(index(x) + RES * (index(y) + RES * index(z))) as usize]
    });
    let choice = default_majorants(&desc);
    assert_eq!(choice.rule, MajorantRule::GridSavesTooLittle, "{choice:?}");
    assert_eq!(choice.resolution, 1);
    assert_eq!(path_settings(&desc).majorant_resolution, 1);
}

/// One value in every voxel of a grid (ad's and cgg-logo's density) and a constant density: no
/// grid, and the rule says why.
#[test]
fn a_uniform_density_keeps_the_global_majorant() {
    let desc = grid_scene(|_, _, z| if z < 2.0 { 0.7 } else { 0.0 });
    let choice = default_majorants(&desc);
    assert_eq!(choice.resolution, 1, "{choice:?}");
    assert!(
        matches!(
            choice.rule,
            MajorantRule::NoTighterGrid | MajorantRule::Homogeneous
        ),
        "{choice:?}"
    );
    let constant = cube_scene(
        8,
        8,
        homogeneous(3.0, 0.5, PhaseDesc::Isotropic),
        BsdfDesc::Null,
        1.0,
    );
    let choice = default_majorants(&constant);
    assert_eq!(
        (choice.resolution, choice.rule),
        (1, MajorantRule::Homogeneous)
    );
}

/// The cell crossings the cost counts are the DDA's: a ray along an axis through the whole box
/// enters `cells - 1` further cells of a grid of `cells` along that axis.
#[test]
fn crossings_follow_the_grid_resolution() {
    let bounds = Aabb::new(Vec3::splat(-0.5), Vec3::splat(0.5));
    for cells in [8, 16, 32] {
        assert_eq!(MajorantGrid::resolution_for(bounds, cells), [cells; 3]);
    }
    let desc = grid_scene(|x, _, _| 0.5 + x);
    let (c8, c32) = (cost(&desc, 8), cost(&desc, 32));
    let ratio = c32.crossings_ratio / c8.crossings_ratio;
    assert!(
        (3.0..5.0).contains(&ratio),
        "32 cells cross {ratio}x as many cells as 8"
    );
}
