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
const SPP: u32 = 256;

/// The generated density with holes times [`SCALES`] per channel, as one three-channel grid
/// (`rgb`), or channel `c`'s alone as a grey grid.
fn medium(channel: Option<usize>) -> MediumDesc {
    let grey = density_with_holes(11);
    let (density, albedo) = match channel {
        None => (
            GridDesc {
                channels: 3,
                data: grey.data.iter().flat_map(|d| SCALES.map(|e| d * e)).collect(),
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
    framed_scene(12, medium(channel), EnvironmentDesc::Constant([1.0, 0.9, 0.8]))
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
        let twins = [0, 1, 2].map(|c| ImageMean::render(&scene(Some(c)), SPP, 2 + c as u32, settings));
        let grey = ImageMean {
            mean: [0, 1, 2].map(|c| twins[c].mean[c]),
            var: [0, 1, 2].map(|c| twins[c].var[c]),
        };
        assert_agree(&format!("density per channel, {estimator:?}"), &grey, &chromatic);
    }
}
