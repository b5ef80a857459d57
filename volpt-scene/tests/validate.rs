//! `validate`, the backstop every assembled scene passes, on descriptions changed in code (the
//! loaders refuse bad values at their lines before it sees them): values inside each limit pass,
//! the limits refuse.

mod common;

use common::*;
use volpt_scene::validate::validate;
use volpt_scene::*;

/// A homogeneous medium in the 2 x 2 x 2 cube, null boundary, constant environment.
fn base() -> SceneDescription {
    let (_dir, path) = scene_file(&medium_scene(
        r#"<medium type="homogeneous" name="interior"/>"#,
    ));
    let desc = load_mitsuba(&path).expect("scene loads");
    validate(&desc, "base").expect("the base scene is valid");
    desc
}

fn refused(desc: &SceneDescription, field: &str) {
    let err = validate(desc, "test").expect_err("should be refused");
    message_of(&err, &[field]);
}

#[test]
fn a_film_with_a_side_of_zero_is_refused() {
    for (width, height) in [(0, 5), (5, 0)] {
        let mut desc = base();
        desc.film.width = width;
        desc.film.height = height;
        refused(&desc, "film");
    }
}

#[test]
fn henyey_greenstein_g_inside_its_open_interval_passes() {
    let mut desc = base();
    desc.medium.phase = PhaseDesc::HenyeyGreenstein { g: 0.5 };
    validate(&desc, "test").expect("g 0.5 is valid");
    desc.medium.phase = PhaseDesc::HenyeyGreenstein { g: -1.0 };
    refused(&desc, "phase g");
}

/// The optical depth is the majorant (scale x largest density) times the box's diagonal: 2 x
/// 2.5e6 x 2 sqrt 3 = 1.7e7 exceeds the 1e7 limit, where a sum of the factors would not.
#[test]
fn optical_depth_is_the_product_of_majorant_and_diagonal() {
    let mut desc = base();
    desc.medium.scale = 2.0;
    desc.medium.density = DensityDesc::Constant(2.5e6);
    refused(&desc, "optical depth");
    desc.medium.density = DensityDesc::Constant(1e6);
    validate(&desc, "test").expect("an optical depth of 6.9e6 is valid");
}

#[test]
fn an_environment_map_with_scale_one_passes_and_a_negative_scale_does_not() {
    let mut desc = base();
    let mut map = LatLongDesc {
        width: 2,
        height: 1,
        rgb: vec![1.0; 6],
        to_world: IDENTITY,
        scale: 1.0,
        rows: LatLongRows::CellCentred,
    };
    desc.environment = EnvironmentDesc::LatLong(map.clone());
    validate(&desc, "test").expect("scale 1 is valid");
    map.scale = -1.0;
    desc.environment = EnvironmentDesc::LatLong(map);
    refused(&desc, "environment map scale");
}

#[test]
fn a_density_grid_with_a_negative_value_is_refused() {
    let mut desc = base();
    let mut grid = GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution: [2, 1, 1],
        channels: 1,
        bounds: desc.boundary.bounds,
        convention: GridConvention::Cell,
        data: vec![1.0, 2.0],
    };
    desc.medium.density = DensityDesc::Grid(grid.clone());
    validate(&desc, "test").expect("a grid of 1 and 2 is valid");
    grid.data[1] = -2.0;
    desc.medium.density = DensityDesc::Grid(grid);
    refused(&desc, "density grid");
}
