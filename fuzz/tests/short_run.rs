//! The short run of every fuzz target that CI does (issue 12): each target's seeds, then
//! deterministic mutations of them for a fixed number of inputs. A panic fails the test; an abort
//! or a huge allocation kills it. The long runs are `fuzz/run` (`docs/reliability.md`).

use volpt_fuzz::{seeds, Mutator, Target};

/// Mutated inputs per target: about a second each on the 2-core CI machine.
const MUTATIONS: usize = 20_000;

/// A DICOM series input is a folder of several files, each parsed twice: a tenth of the inputs
/// keeps its short run within the same time as the others'.
const SERIES_MUTATIONS: usize = MUTATIONS / 10;

fn short_run(target: Target) {
    let mutations = match target {
        Target::DicomSeries => SERIES_MUTATIONS,
        _ => MUTATIONS,
    };
    let seeds = seeds(target);
    assert!(!seeds.is_empty(), "{} has no seeds", target.name());
    for seed in &seeds {
        target.run(seed);
    }
    let mut mutator = Mutator::new(target as u64 + 1);
    let mut input = seeds[0].clone();
    for i in 0..mutations {
        // Mostly mutate a seed afresh; sometimes keep mutating the last input (deeper changes).
        if i % 4 != 3 {
            input = seeds[i % seeds.len()].clone();
        }
        input = mutator.mutate(&input);
        target.run(&input);
    }
}

#[test]
fn mitsuba_xml() {
    short_run(Target::MitsubaXml);
}

#[test]
fn vol() {
    short_run(Target::Vol);
}

#[test]
fn metaimage() {
    short_run(Target::MetaImage);
}

#[test]
fn vtk_legacy() {
    short_run(Target::VtkLegacy);
}

#[test]
fn vtk_xml() {
    short_run(Target::VtkXml);
}

#[test]
fn toml_raw() {
    short_run(Target::TomlRaw);
}

#[test]
fn transfer_function() {
    short_run(Target::TransferFunction);
}

#[test]
fn exr_envmap() {
    short_run(Target::ExrEnvmap);
}

#[test]
fn vdb() {
    short_run(Target::Vdb);
}

#[test]
fn nrrd() {
    short_run(Target::Nrrd);
}

#[test]
fn tiff_stack() {
    short_run(Target::TiffStack);
}

#[test]
fn dicom_series() {
    short_run(Target::DicomSeries);
}

#[test]
fn film_file() {
    short_run(Target::FilmFile);
}

#[test]
fn viewer_message() {
    short_run(Target::ViewerMessage);
}
