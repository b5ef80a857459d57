//! A density per channel: Mitsuba 3's three-channel `sigma_t` `gridvolume` and a TOML scene's
//! three-channel `[volume]` file load as a chromatic grid (a grid whose channels agree in every
//! sample loads as the grey grid it is, one value different keeps it chromatic), and bad values or
//! an impossible combination are refused with the file and the field named.

mod common;

use common::*;
use volpt_scene::{
    builder_for, load_mitsuba, Config, DensityDesc, GridLookup, SceneAssembler, SceneError, VolGrid,
};

/// A 2x2x2 grid of three channels, `edit`ed.
fn rgb_grid(edit: impl FnOnce(&mut [f32])) -> VolGrid {
    let mut data: Vec<f32> = (0..8)
        .flat_map(|i| [i as f32, 2.0 * i as f32, 4.0 * i as f32])
        .collect();
    edit(&mut data);
    VolGrid {
        channels: 3,
        data,
        ..density_grid([2, 2, 2], unit_bounds())
    }
}

/// Equal channels in every sample: a grey grid spelt in three.
fn equal_channels(data: &mut [f32]) {
    for s in data.chunks_exact_mut(3) {
        s[1] = s[0];
        s[2] = s[0];
    }
}

fn mitsuba(grid: &VolGrid, extra: &str) -> Result<volpt_scene::SceneDescription, SceneError> {
    let text = medium_scene(&format!(
        r#"<medium type="heterogeneous" name="interior">
            <volume name="sigma_t" type="gridvolume"><string name="filename" value="rgb.vol"/></volume>
            <float name="scale" value="2"/>{extra}
        </medium>"#
    ));
    let (dir, path) = scene_file(&text);
    write_grid(dir.path(), "rgb.vol", grid);
    load_mitsuba(&path)
}

fn toml(grid: &VolGrid, extra: &str) -> Result<volpt_scene::SceneDescription, SceneError> {
    let dir = tempfile::tempdir().unwrap();
    write_grid(dir.path(), "rgb.vol", grid);
    let path = dir.path().join("scene.toml");
    std::fs::write(
        &path,
        format!("[volume]\nfile = \"rgb.vol\"\nscale = 2.0\n{extra}"),
    )
    .unwrap();
    SceneAssembler::new(Config::default()).assemble(builder_for(&path)?.as_ref())
}

fn density(desc: &volpt_scene::SceneDescription) -> &volpt_scene::GridDesc {
    let DensityDesc::Grid(grid) = &desc.medium.density else {
        panic!("a grid density expected, found {:?}", desc.medium.density)
    };
    grid
}

#[test]
fn a_three_channel_sigma_t_loads_as_a_density_per_channel_in_both_spellings() {
    let grid = rgb_grid(|_| {});
    for desc in [mitsuba(&grid, "").unwrap(), toml(&grid, "").unwrap()] {
        assert_eq!(density(&desc).channels, 3);
        assert_eq!(density(&desc).data, grid.data);
        assert_eq!(desc.medium.scale, 2.0);
        assert!(desc.medium.is_chromatic());
        assert_eq!(desc.medium.max_extinction(), 2.0 * 28.0);
    }
}

/// The edge of the rule: channels that agree in every sample (bit for bit) load as one channel,
/// and a grid of one sample's blue one ulp larger stays three.
#[test]
fn a_three_channel_sigma_t_of_equal_channels_loads_as_a_grey_grid() {
    let grey = rgb_grid(equal_channels);
    let beside = rgb_grid(|d| {
        equal_channels(d);
        d[3 * 5 + 2] = f32::from_bits(d[3 * 5 + 2].to_bits() + 1);
    });
    for (desc, beside) in [
        (mitsuba(&grey, "").unwrap(), mitsuba(&beside, "").unwrap()),
        (toml(&grey, "").unwrap(), toml(&beside, "").unwrap()),
    ] {
        assert_eq!(density(&desc).channels, 1);
        assert_eq!(
            density(&desc).data,
            (0..8).map(|i| i as f32).collect::<Vec<_>>()
        );
        assert!(!desc.medium.is_chromatic());
        assert_eq!(density(&beside).channels, 3);
        assert!(beside.medium.is_chromatic());
    }
}

#[test]
fn a_negative_channel_or_a_transfer_function_beside_it_is_refused() {
    let negative = rgb_grid(|d| d[3 * 6 + 1] = -1.0);
    for err in [
        mitsuba(&negative, "").unwrap_err(),
        toml(&negative, "").unwrap_err(),
    ] {
        message_of(&err, &["rgb.vol", "voxel (x=0, y=1, z=1)", ">= 0", "-1"]);
    }
    let grid = rgb_grid(|_| {});
    let tf_dir = tempfile::tempdir().unwrap();
    let tf = tf_dir.path().join("tf.txt");
    std::fs::write(&tf, "0 0.5 0.5 0.5\n30 0.9 0.9 0.9\n").unwrap();
    let err = toml(
        &grid,
        &format!(
            "[albedo]\ntransfer_function = {:?}\n",
            tf.display().to_string()
        ),
    )
    .unwrap_err();
    message_of(&err, &["albedo.transfer_function", "three channels"]);
}

/// A chromatic grid is read trilinearly or nearest, from dense samples; a texture lookup is
/// refused when the scene is checked.
#[test]
fn a_density_per_channel_with_texture_lookups_is_refused() {
    let mut desc = toml(&rgb_grid(|_| {}), "").unwrap();
    desc.medium.lookup = GridLookup::Nearest;
    volpt_scene::validate::validate(&desc, "scene.toml").unwrap();
    desc.medium.lookup = GridLookup::Texture;
    let err = volpt_scene::validate::validate(&desc, "scene.toml").unwrap_err();
    message_of(
        &err,
        &[
            "grid lookup",
            "trilinear or nearest lookups of dense grids",
            "Texture",
        ],
    );
}

/// Mitsuba 3's `filter_type`: `nearest` on every grid of the medium reads them nearest (an
/// exported material-indexed volume's grids), `trilinear` or none trilinearly, and grids whose
/// filters differ trilinearly (with a warning).
#[test]
fn a_gridvolume_filter_type_of_nearest_reads_the_medium_nearest() {
    let grid = rgb_grid(|_| {});
    let nearest = r#"<string name="filter_type" value="nearest"/>"#;
    let albedo = |filter: &str| {
        format!(
            r#"<volume name="albedo" type="gridvolume"><string name="filename" value="albedo.vol"/>{filter}</volume>"#
        )
    };
    let load = |sigma_filter: &str, albedo: &str| {
        let text = medium_scene(&format!(
            r#"<medium type="heterogeneous" name="interior">
                <volume name="sigma_t" type="gridvolume"><string name="filename" value="rgb.vol"/>{sigma_filter}</volume>
                {albedo}
            </medium>"#
        ));
        let (dir, path) = scene_file(&text);
        write_grid(dir.path(), "rgb.vol", &grid);
        let albedo_grid = VolGrid {
            data: vec![0.5; 24],
            ..grid.clone()
        };
        write_grid(dir.path(), "albedo.vol", &albedo_grid);
        load_mitsuba(&path).unwrap().medium.lookup
    };
    assert_eq!(load(nearest, ""), GridLookup::Nearest);
    assert_eq!(load(nearest, &albedo(nearest)), GridLookup::Nearest);
    assert_eq!(load("", ""), GridLookup::Trilinear);
    assert_eq!(load(nearest, &albedo("")), GridLookup::Trilinear);
}
