//! `<emitter type="envmap">`: OpenEXR maps read in both Mitsuba dialects, and every kind of bad map
//! reported with the scene file, the line of the field and the problem.

mod common;

use std::path::Path;

use common::*;
use exr::prelude::WritableImage;
use exr::prelude::{write_rgb_file, AnyChannel, AnyChannels, FlatSamples, Image, SmallVec};
use volpt_scene::error::EnvmapProblem;
use volpt_scene::{load_mitsuba, EnvironmentDesc, LatLongDesc, LatLongRows, SceneError};

/// A scene of dialect `version` lit by `emitter`.
fn scene(version: &str, emitter: &str) -> String {
    cube_scene(
        "        <bsdf type=\"null\"/>\n        <medium type=\"homogeneous\" name=\"interior\">\
         <float name=\"sigmaT\" value=\"1\"/><float name=\"albedo\" value=\"0.5\"/></medium>",
    )
    .replace("3.0.0", version)
    .replace("</scene>", &format!("{emitter}\n</scene>"))
}

fn envmap(filename: &str, extra: &str) -> String {
    format!(
        "    <emitter type=\"envmap\">\n        <string name=\"filename\" value=\"{filename}\"/>\n\
         {extra}    </emitter>"
    )
}

/// Texel `(x, y)` of the test maps: distinct in every pixel and channel.
fn texel(x: usize, y: usize) -> (f32, f32, f32) {
    let i = (y * 4 + x) as f32;
    (i, 0.5 * i + 1.0, 0.25)
}

fn write_map(dir: &Path, name: &str, width: usize, height: usize) {
    write_rgb_file(dir.join(name), width, height, texel).expect("write EXR");
}

fn write_channels(dir: &Path, name: &str, channels: &[(&str, Vec<f32>)], size: (usize, usize)) {
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .iter()
        .map(|(n, v)| AnyChannel::new(*n, FlatSamples::F32(v.clone())))
        .collect();
    Image::from_channels(size, AnyChannels::sort(list))
        .write()
        .to_file(dir.join(name))
        .expect("write EXR");
}

/// Loads `text` (with the map files already in `dir`).
fn load(dir: &Path, text: &str) -> Result<LatLongDesc, SceneError> {
    let path = dir.join("scene.xml");
    std::fs::write(&path, text).expect("write scene");
    match load_mitsuba(&path)?.environment {
        EnvironmentDesc::LatLong(map) => Ok(map),
        other => panic!("expected a lat-long environment, found {other:?}"),
    }
}

fn line_of(text: &str, needle: &str) -> usize {
    1 + text[..text.find(needle).expect("needle in scene")]
        .matches('\n')
        .count()
}

#[test]
fn mitsuba3_envmap_loads_texels_scale_rotation_and_pole_to_pole_rows() {
    let dir = tempfile::tempdir().unwrap();
    write_map(dir.path(), "sky.exr", 4, 3);
    let text = scene(
        "3.0.0",
        &envmap(
            "sky.exr",
            "        <float name=\"scale\" value=\"2.5\"/>\n\
             \x20       <transform name=\"to_world\"><rotate y=\"1\" angle=\"90\"/>\
             <translate x=\"7\"/></transform>\n",
        ),
    );
    let map = load(dir.path(), &text).unwrap();
    assert_eq!((map.width, map.height), (4, 3));
    assert_eq!(map.rgb.len(), 36);
    for y in 0..3 {
        for x in 0..4 {
            let (r, g, b) = texel(x, y);
            let i = 3 * (y * 4 + x);
            assert_eq!(map.rgb[i..i + 3], [r, g, b], "texel ({x}, {y})");
        }
    }
    assert_eq!(map.scale, 2.5);
    assert_eq!(map.rows, LatLongRows::PoleToPole);
    assert_matrix(
        &map.to_world,
        &[
            [0.0, 0.0, 1.0, 7.0],
            [0.0, 1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    );
}

#[test]
fn mitsuba06_envmap_uses_to_world_spelling_and_cell_centred_rows() {
    let dir = tempfile::tempdir().unwrap();
    write_map(dir.path(), "sky.exr", 1, 1);
    let text = scene(
        "0.6.0",
        &envmap(
            "sky.exr",
            "        <transform name=\"toWorld\"><rotate x=\"1\" angle=\"180\"/></transform>\n\
             \x20       <float name=\"samplingWeight\" value=\"1\"/>\n",
        ),
    );
    let map = load(dir.path(), &text).unwrap();
    assert_eq!((map.width, map.height, map.scale), (1, 1, 1.0));
    assert_eq!(map.rows, LatLongRows::CellCentred);
    assert_eq!(map.rgb, [0.0, 1.0, 0.25]);
    assert!((map.to_world[1][1] + 1.0).abs() < 1e-6 && (map.to_world[2][2] + 1.0).abs() < 1e-6);
}

#[test]
fn luminance_only_map_is_grey() {
    let dir = tempfile::tempdir().unwrap();
    let y: Vec<f32> = (0..6).map(|i| i as f32).collect();
    write_channels(dir.path(), "grey.exr", &[("Y", y)], (2, 3));
    let map = load(dir.path(), &scene("3.0.0", &envmap("grey.exr", ""))).unwrap();
    assert_eq!(map.rgb[9..12], [3.0; 3]);
}

/// Loads a broken scene and checks the message names the scene file, the line of `needle`, and
/// each of `parts`.
fn error(dir: &Path, text: &str, needle: &str, parts: &[&str]) -> SceneError {
    let err = load(dir, text).expect_err("the scene should not load");
    let at = format!("scene.xml:{}:", line_of(text, needle));
    let mut all = vec![at.as_str()];
    all.extend_from_slice(parts);
    message_of(&err, &all);
    err
}

fn inner(err: &SceneError) -> &SceneError {
    match err {
        SceneError::Referenced { error, .. } => error,
        other => panic!("expected an error in the referenced map, found {other}"),
    }
}

#[test]
fn missing_map_names_the_file_and_the_filename_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = scene("3.0.0", &envmap("nowhere.exr", ""));
    let err = error(
        dir.path(),
        &text,
        "name=\"filename\"",
        &["<string name=\"filename\">", "nowhere.exr"],
    );
    assert!(matches!(inner(&err), SceneError::Io { .. }), "{err}");
}

#[test]
fn map_without_rgb_channels_lists_what_it_has() {
    let dir = tempfile::tempdir().unwrap();
    write_channels(
        dir.path(),
        "depth.exr",
        &[("Z", vec![1.0; 6]), ("R", vec![1.0; 6])],
        (2, 3),
    );
    let text = scene("3.0.0", &envmap("depth.exr", ""));
    let err = error(
        dir.path(),
        &text,
        "name=\"filename\"",
        &["depth.exr", "expected R, G and B channels", "R, Z"],
    );
    assert!(matches!(
        inner(&err),
        SceneError::Envmap {
            problem: EnvmapProblem::Channels { .. },
            ..
        }
    ));
}

#[test]
fn non_finite_or_negative_texels_are_named_by_position_and_channel() {
    for (value, shown) in [(f32::NAN, "NaN"), (-0.5, "-0.5"), (f32::INFINITY, "inf")] {
        let dir = tempfile::tempdir().unwrap();
        let mut g = vec![1.0; 6];
        g[5] = value; // (x=1, y=2) in a 2 x 3 map
        write_channels(
            dir.path(),
            "bad.exr",
            &[("R", vec![1.0; 6]), ("G", g), ("B", vec![1.0; 6])],
            (2, 3),
        );
        let text = scene("3.0.0", &envmap("bad.exr", ""));
        error(
            dir.path(),
            &text,
            "name=\"filename\"",
            &[
                "bad.exr",
                "pixel (x=1, y=2) channel G",
                "radiance >= 0",
                shown,
            ],
        );
    }
}

#[test]
fn other_image_formats_ask_for_exr() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["sky.png", "sky.HDR"] {
        let text = scene("3.0.0", &envmap(name, ""));
        error(
            dir.path(),
            &text,
            "name=\"filename\"",
            &[name, "not supported", "convert it to .exr"],
        );
    }
}

#[test]
fn file_that_is_not_exr_is_a_decode_error() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("sky.exr"), b"#?RADIANCE\nnot an exr").unwrap();
    let text = scene("3.0.0", &envmap("sky.exr", ""));
    error(
        dir.path(),
        &text,
        "name=\"filename\"",
        &["sky.exr", "not a readable OpenEXR image"],
    );
}

#[test]
fn mitsuba3_refuses_maps_smaller_than_two_by_three() {
    let dir = tempfile::tempdir().unwrap();
    write_map(dir.path(), "tiny.exr", 2, 2);
    let text = scene("3.0.0", &envmap("tiny.exr", ""));
    error(
        dir.path(),
        &text,
        "name=\"filename\"",
        &["tiny.exr", "at least 2 x 3 pixels, found 2 x 2"],
    );
}

#[test]
fn scaled_or_sheared_to_world_is_an_error_at_the_transform() {
    let dir = tempfile::tempdir().unwrap();
    write_map(dir.path(), "sky.exr", 4, 3);
    for step in [
        "<scale value=\"2\"/>",
        "<matrix value=\"1 0.5 0 0 1 0 0 0 1\"/>",
    ] {
        let text = scene(
            "3.0.0",
            &envmap(
                "sky.exr",
                &format!("        <transform name=\"to_world\">{step}</transform>\n"),
            ),
        );
        error(
            dir.path(),
            &text,
            "name=\"to_world\"",
            &["<transform name=\"to_world\">", "a rotation or mirroring"],
        );
    }
}

#[test]
fn negative_scale_and_missing_filename_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    write_map(dir.path(), "sky.exr", 4, 3);
    let text = scene(
        "3.0.0",
        &envmap("sky.exr", "        <float name=\"scale\" value=\"-1\"/>\n"),
    );
    error(dir.path(), &text, "name=\"scale\"", &["a scale >= 0", "-1"]);

    let text = scene(
        "3.0.0",
        "    <emitter type=\"envmap\">\n        <float name=\"scale\" value=\"1\"/>\n    </emitter>",
    );
    error(
        dir.path(),
        &text,
        "type=\"envmap\"",
        &["missing <string name=\"filename\">"],
    );
}
