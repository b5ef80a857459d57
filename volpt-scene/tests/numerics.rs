//! `numerics`: the check that `f32` positions resolve the medium's mean free path, on the largest
//! extinction (scale x largest density) of descriptions changed in code.

mod common;

use common::*;
use volpt_scene::numerics::{
    check_position_resolution, check_position_resolution_settings, max_extinction,
};
use volpt_scene::validate::CheckedData;
use volpt_scene::*;

/// A homogeneous medium in the cube [-1, 1]^3: positions near 1 are 2^-23 apart.
fn base() -> SceneDescription {
    let (_dir, path) = scene_file(&medium_scene(
        r#"<medium type="homogeneous" name="interior"/>"#,
    ));
    load_mitsuba(&path).expect("scene loads")
}

#[test]
fn the_largest_extinction_is_the_scale_times_the_largest_density() {
    let mut desc = base();
    desc.medium.scale = 3.0;
    desc.medium.density = DensityDesc::Constant(5.0);
    assert_eq!(max_extinction(&desc.medium), 15.0);
    desc.medium.density = DensityDesc::Grid(GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution: [2, 1, 1],
        channels: 1,
        bounds: unit_bounds(),
        convention: GridConvention::Cell,
        data: vec![0.5, 4.0],
    });
    assert_eq!(max_extinction(&desc.medium), 12.0);
}

/// In [-1, 1]^3 the mean free path must span 16 spacings of 2^-23: an extinction of at most
/// 2^19 = 1024 x 512, met exactly. 1024 x 513 is refused, where a sum of the factors would pass;
/// the message names the box's largest coordinate and the largest extinction it allows.
#[test]
fn the_mean_free_path_must_span_sixteen_position_steps() {
    let mut desc = base();
    let source = std::path::Path::new("scene.xml");
    desc.medium.scale = 1024.0;
    desc.medium.density = DensityDesc::Constant(512.0);
    check_position_resolution(&desc, source).expect("a mean free path of exactly 16 steps");
    desc.medium.density = DensityDesc::Constant(513.0);
    let err = check_position_resolution(&desc, source).expect_err("under 16 steps");
    message_of(
        &err,
        &[
            "scene.xml",
            "coordinates up to ~1.000e0 are 1.192e-7 apart",
            "an extinction of at most 5.243e5",
            "a largest extinction of 5.25312e5",
        ],
    );
}

/// A scene's settings are checked again at every change (a viewer's camera at every frame) with
/// its grids' largest values as found when loaded: the same verdict as reading the grid, at the
/// same bound (1024 x 512 passes, 1024 x 513 is refused), and the grid's values are not read again
/// (a grid whose values changed behind the check's back keeps the verdict its checked data gives).
#[test]
fn the_settings_check_takes_the_grids_largest_density_from_the_checked_data() {
    let mut desc = base();
    let source = std::path::Path::new("scene.xml");
    desc.medium.scale = 1024.0;
    let grid = |largest: f32| {
        DensityDesc::Grid(GridDesc {
            layout: volpt_scene::SampleLayout::Dense,
            resolution: [2, 1, 1],
            channels: 1,
            bounds: unit_bounds(),
            convention: GridConvention::Cell,
            data: vec![0.5, largest],
        })
    };
    let checked = |largest_density: f32| CheckedData {
        largest_density,
        largest_albedo: 0.0,
    };
    for (largest, passes) in [(512.0, true), (513.0, false)] {
        desc.medium.density = grid(largest);
        let read = check_position_resolution(&desc, source);
        let settings = check_position_resolution_settings(&desc, source, checked(largest));
        assert_eq!(read.is_ok(), passes, "{largest}: {read:?}");
        assert_eq!(settings.is_ok(), passes, "{largest}: {settings:?}");
    }
    desc.medium.density = grid(1e9);
    check_position_resolution_settings(&desc, source, checked(512.0))
        .expect("the checked data's largest density, not the grid's values");
}
