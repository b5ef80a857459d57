//! A density per channel (Mitsuba 3's RGB `sigma_t` `gridvolume`, a three-channel `[volume]`
//! grid) through the factory: each channel of its render equals, in expectation, the grey render
//! of that channel's density grid and albedo (the per-channel identity, which no weight can be
//! tuned to pass), with the majorant grid the factory builds from each channel's samples, path
//! tracing and next-event estimation; and the factory picks the chromatic part for it, and the
//! grey parts for its one-channel twin.

use volpt_core::{Estimator, PathSettings};
use volpt_render::Variant;
use volpt_scene::description::*;
use volpt_tests::agreement::{assert_agree, ImageMean};
use volpt_tests::generated::{density_with_holes, framed_scene};
use volpt_tests::plain_path_tracing;

/// Each channel's extinction per unit density: channels 5x apart, the cyan resin's regime.
const SCALES: [f32; 3] = [1.2, 3.0, 6.0];
const ALBEDO: [f32; 3] = [0.9, 0.7, 0.5];
const SPP: u32 = 12288;

/// The generated density with holes times [`SCALES`] per channel, as one three-channel grid
/// (`rgb`), or channel `c`'s alone as a grey grid.
fn medium(channel: Option<usize>) -> MediumDesc {
    let grey = density_with_holes(11);
    let (density, albedo) = match channel {
        None => (
            GridDesc {
                channels: 3,
                data: grey
                    .data
                    .iter()
                    .flat_map(|d| SCALES.map(|e| d * e))
                    .collect(),
                ..grey
            },
            ALBEDO,
        ),
        Some(c) => (
            GridDesc {
                data: grey.data.iter().map(|d| d * SCALES[c]).collect(),
                ..grey
            },
            [ALBEDO[c]; 3],
        ),
    };
    MediumDesc {
        density: DensityDesc::Grid(density),
        scale: 1.0,
        albedo: AlbedoDesc::Constant(albedo),
        phase: PhaseDesc::HenyeyGreenstein { g: 0.4 },
        lookup: Default::default(),
        storage: Default::default(),
    }
}

fn scene(channel: Option<usize>) -> SceneDescription {
    framed_scene(
        12,
        medium(channel),
        EnvironmentDesc::Constant([1.0, 0.9, 0.8]),
    )
}

#[test]
fn a_density_per_channel_is_rendered_by_the_chromatic_part_and_its_grey_twins_by_grey_ones() {
    assert_eq!(Variant::of(&scene(None)).medium.name(), "chromatic");
    assert!(scene(None).medium.is_chromatic());
    for c in 0..3 {
        assert_ne!(Variant::of(&scene(Some(c))).medium.name(), "chromatic");
        assert!(!scene(Some(c)).medium.is_chromatic());
    }
}

/// The per-channel identity of a density per channel, behind an index-matched boundary with the
/// factory's per-channel majorant grid: channel `c` of the chromatic render against the grey
/// render of channel `c`'s grid, path tracing and next-event estimation (1% is at least 10
/// standard errors of each difference, asserted; the window is 5).
#[test]
fn each_channel_of_a_density_per_channel_renders_as_its_grey_grid() {
    for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
        let settings = PathSettings {
            estimator,
            ..plain_path_tracing()
        };
        let chromatic = ImageMean::render(&scene(None), SPP, 1, settings);
        let twins =
            [0, 1, 2].map(|c| ImageMean::render(&scene(Some(c)), SPP, 2 + c as u32, settings));
        let grey = ImageMean {
            mean: [0, 1, 2].map(|c| twins[c].mean[c]),
            var: [0, 1, 2].map(|c| twins[c].var[c]),
        };
        assert_agree(
            &format!("density per channel, {estimator:?}"),
            &grey,
            &chromatic,
        );
    }
}

/// A print of three materials (one `g`, as a Mitsuba 3 medium holds) in a 6 x 5 x 4 index grid
/// over the generated scenes' box.
fn print() -> MediumDesc {
    use volpt_scene::material::{IndexedDesc, MaterialDesc};
    let material = |name: &str, sigma_s: [f32; 3], sigma_a: [f32; 3]| MaterialDesc {
        name: name.into(),
        sigma_s,
        sigma_a,
        g: 0.3,
        colour: None,
    };
    let materials = vec![
        material("cyan", [4.0, 6.0, 7.0], [6.0, 0.8, 0.2]),
        material("magenta", [6.0, 4.0, 6.5], [0.3, 5.0, 0.6]),
        material("white", [12.0, 12.0, 12.0], [0.02, 0.03, 0.05]),
    ];
    let indices: Vec<u8> = (0..6 * 5 * 4u32)
        .map(|i| ((i % 6) / 2 + (i / 6 % 5) / 2 + i / 30) as u8 % 3)
        .collect();
    let bounds = Bounds {
        min: [-0.5; 3],
        max: [0.5; 3],
    };
    let indexed = IndexedDesc::new(
        std::path::Path::new("print.raw"),
        materials,
        [6, 5, 4],
        bounds,
        &indices,
    )
    .unwrap();
    MediumDesc {
        phase: indexed.phase(),
        density: DensityDesc::Indexed(indexed),
        scale: 0.5,
        albedo: AlbedoDesc::Constant([0.0; 3]),
        lookup: Default::default(),
        storage: Default::default(),
    }
}

/// The material-indexed volume renders as its expanded RGB grids: its Mitsuba 3 export (the table
/// expanded per voxel into `sigma_t` and `albedo` grids, `filter_type` nearest) loaded back is a
/// density per channel read nearest, whose image equals the indexed volume's in expectation
/// (each with the majorant grid the factory builds its own way; 1% is at least 10 standard errors,
/// asserted; the window is 5), path tracing and next-event estimation.
#[test]
fn an_indexed_volume_renders_as_its_exported_rgb_grids() {
    let indexed = framed_scene(12, print(), EnvironmentDesc::Constant([1.0, 0.9, 0.8]));
    let dir = tempfile::tempdir().unwrap();
    let written = volpt_scene::mitsuba::write_mitsuba3(&indexed, dir.path(), "print").unwrap();
    let expanded = volpt_scene::load_mitsuba(&written[0]).unwrap();
    assert_eq!(expanded.medium.lookup, GridLookup::Nearest);
    let DensityDesc::Grid(grid) = &expanded.medium.density else {
        panic!("{:?}", expanded.medium.density)
    };
    assert_eq!((grid.resolution, grid.channels), ([6, 5, 4], 3));
    assert_eq!(Variant::of(&expanded).medium.name(), "chromatic");
    for estimator in [Estimator::PathTracing, Estimator::NextEvent] {
        let settings = PathSettings {
            estimator,
            ..plain_path_tracing()
        };
        let a = ImageMean::render(&indexed, SPP, 1, settings);
        let b = ImageMean::render(&expanded, SPP, 2, settings);
        assert_agree(&format!("indexed vs its RGB grids, {estimator:?}"), &a, &b);
    }
}
