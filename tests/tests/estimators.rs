//! Estimator against estimator on generated heterogeneous media (`volpt_tests::generated`: a
//! density with holes, an albedo well below 1 that varies per voxel and channel), under a
//! constant and a lat-long environment, with nothing read from beside the checkout: the guards
//! that CI runs (it has no `../shared/data`, so the smoke and bucky comparisons of
//! `heterogeneous.rs` are skipped there).
//!
//! Every test compares an estimator with the plain one on the same scene: path tracing, no
//! roulette, the majorant grid, dense trilinear lookups. Each is unbiased, so the image means agree
//! up to noise; the renders are sized so that a 1% difference is at least 10 standard errors of
//! the difference (`agreement::MARGIN`, asserted), and the window is 5 (`agreement::WINDOW`), so a
//! 0.5% bias fails. Seeds are fixed: the outcome is the same on every run.

use volpt_core::{Estimator, PathSettings, Roulette};
use volpt_scene::description::*;
use volpt_tests::agreement::{assert_agree, ImageMean};
use volpt_tests::generated::{broad_sun_sky, framed_scene, heterogeneous_medium, LOW_ALBEDO};

/// Pixels per side: every pixel sees the medium.
const SIZE: u32 = 12;

/// The plain estimator: path tracing, no roulette, depth unlimited, a majorant grid of 16 cells
/// along the box.
fn plain() -> PathSettings {
    PathSettings {
        max_depth: PathSettings::UNLIMITED,
        rr_depth: PathSettings::UNLIMITED,
        majorant_resolution: 16,
        estimator: Estimator::PathTracing,
        ..PathSettings::default()
    }
}

fn nee() -> PathSettings {
    PathSettings {
        estimator: Estimator::NextEvent,
        ..plain()
    }
}

/// Extinction up to 6 per unit length over the unit cube (an optical depth of about 3 across
/// it), forward scattering, albedo in `albedo`.
fn scene(albedo: (f32, f32), environment: EnvironmentDesc) -> SceneDescription {
    framed_scene(SIZE, heterogeneous_medium(6.0, albedo, 0.4), environment)
}

fn constant_sky() -> SceneDescription {
    scene(LOW_ALBEDO, EnvironmentDesc::Constant([1.0, 0.9, 0.8]))
}

fn lat_long_sky() -> SceneDescription {
    scene(LOW_ALBEDO, broad_sun_sky())
}

/// Each candidate against `reference` on `desc`, `spp` samples per pixel for every render, the
/// reference rendered once; all renders with different seeds, so independent.
fn compare(
    desc: &SceneDescription,
    spp: u32,
    reference: PathSettings,
    candidates: &[(&str, PathSettings)],
) {
    let start = std::time::Instant::now();
    let a = ImageMean::render(desc, spp, 1, reference);
    for (seed, (name, settings)) in (2..).zip(candidates) {
        let b = ImageMean::render(desc, spp, seed, *settings);
        assert_agree(name, &a, &b);
    }
    eprintln!(
        "{} renders of {spp} spp: {:.1} s",
        1 + candidates.len(),
        start.elapsed().as_secs_f64()
    );
}

/// Next-event estimation (shadow rays by ratio tracking through the holes and the majorant
/// grid, MIS with the phase function) against path tracing, under a constant sky and under a
/// lat-long sky whose sun the environment sampling favours.
#[test]
fn next_event_estimation_matches_path_tracing_on_a_generated_medium() {
    compare(
        &constant_sky(),
        SPP_CONSTANT_NEE,
        plain(),
        &[("nee, constant sky", nee())],
    );
    compare(
        &lat_long_sky(),
        SPP_LAT_LONG_NEE,
        plain(),
        &[("nee, lat-long sky", nee())],
    );
}

/// The global majorant against the majorant grid, for free flights (delta tracking) and shadow
/// rays (ratio tracking) alike: under NEE both walk the grid.
#[test]
fn global_majorant_matches_the_majorant_grid_on_a_generated_medium() {
    let global = PathSettings {
        majorant_resolution: 1,
        ..nee()
    };
    compare(
        &lat_long_sky(),
        SPP_GLOBAL,
        nee(),
        &[("global majorant, nee, lat-long sky", global)],
    );
}

/// Each roulette rule from the first interaction on against no roulette, in a medium of albedo
/// 0.5 to 0.98: the throughput falls at every collision, so both rules end paths from the first
/// one, and where the albedo is above 0.95 Mitsuba's rule caps the survival probability (and its
/// paths' throughput grows) while the thesis's keeps every path whose throughput has not fallen.
#[test]
fn each_roulette_rule_matches_no_roulette_on_a_generated_medium() {
    let rule = |roulette| PathSettings {
        rr_depth: 0,
        roulette,
        ..plain()
    };
    compare(
        &scene((0.5, 0.98), EnvironmentDesc::Constant([1.0, 0.9, 0.8])),
        SPP_ROULETTE,
        plain(),
        &[
            ("Mitsuba's roulette", rule(Roulette::Mitsuba)),
            (
                "the thesis's throughput roulette",
                rule(Roulette::Throughput),
            ),
        ],
    );
}

/// Every grid lookup against dense trilinear reads of the same grids: the any-layout reads
/// (bricked storage) compute the same trilinear function, the texture filter approximates it
/// (weights of 8 fractional bits), half-precision texels hold the samples to 2^-10; none may move
/// the image by as much as 0.5%.
#[test]
fn every_grid_lookup_matches_dense_trilinear_on_a_generated_medium() {
    let desc = constant_sky();
    let with = |lookup, storage| {
        let mut d = desc.clone();
        d.medium.lookup = lookup;
        d.medium.storage = storage;
        d
    };
    let a = ImageMean::render(&desc, SPP_LOOKUP, 1, plain());
    for (seed, (name, lookup, storage)) in (2..).zip([
        (
            "any-layout reads (bricked)",
            GridLookup::Trilinear,
            GridStorage::Bricked,
        ),
        ("texture filter", GridLookup::Texture, GridStorage::Dense),
        (
            "half-precision texture",
            GridLookup::TextureHalf,
            GridStorage::Dense,
        ),
    ]) {
        let b = ImageMean::render(&with(lookup, storage), SPP_LOOKUP, seed, plain());
        assert_agree(name, &a, &b);
    }
}

// Samples per pixel, sized from pilot renders of 256 spp: the factor by which those fell short
// of 1% = 10 standard errors in the worst channel (in brackets), times 1.3 to spare.
/// (x23.7)
const SPP_CONSTANT_NEE: u32 = 8192;
/// (x76.4: path tracing rarely finds the sun)
const SPP_LAT_LONG_NEE: u32 = 25600;
/// (x34.8)
const SPP_GLOBAL: u32 = 11520;
/// (x18.2)
const SPP_ROULETTE: u32 = 6144;
/// (x25.0)
const SPP_LOOKUP: u32 = 8320;
