//! One test per kind of bad input: each asserts the message names the file, the line and the
//! field, so a user can find and fix the problem.

mod common;

use std::path::Path;

use common::*;
use volpt_scene::{load_mitsuba, AlbedoDesc, DensityDesc, SceneError};

/// The 1-based line of the first occurrence of `needle` in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle:?} not in scene"));
    1 + text[..at].matches('\n').count()
}

/// Loads `text` and returns the error, asserting it is at `scene.xml:<line of needle>`.
fn error_at(text: &str, needle: &str) -> SceneError {
    let (_dir, path) = scene_file(text);
    let err = load_mitsuba(&path).expect_err("the scene should not load");
    message_of(&err, &[&format!("scene.xml:{}:", line_of(text, needle))]);
    err
}

#[test]
fn malformed_xml_names_file_and_line() {
    let text = "<scene version=\"3.0.0\">\n  <sensor type=\"perspective\">\n  </sensr>\n</scene>\n";
    let err = error_at(text, "</sensr>");
    assert!(matches!(err, SceneError::Xml { line: 3, .. }), "{err}");
    message_of(&err, &["malformed XML"]);
}

#[test]
fn unclosed_element_names_where_it_opened() {
    let text = "<scene version=\"3.0.0\">\n  <sensor type=\"perspective\">\n";
    let (_dir, path) = scene_file(text);
    let err = load_mitsuba(&path).unwrap_err();
    message_of(&err, &["scene.xml:", "<sensor> opened at line 2"]);
}

#[test]
fn missing_scene_file_names_it() {
    let err = load_mitsuba(Path::new("/nonexistent/nowhere/scene.xml")).unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }));
    message_of(&err, &["/nonexistent/nowhere/scene.xml"]);
}

#[test]
fn scene_without_version_is_an_error() {
    let err = error_at("<scene>\n</scene>\n", "<scene>");
    message_of(&err, &["version"]);
}

const GRID_MEDIUM: &str = r#"<medium type="heterogeneous" name="interior">
            <volume name="density" type="gridvolume">
                <string name="filename" value="density.vol"/>
            </volume>
        </medium>"#;

#[test]
fn missing_vol_file_names_both_files() {
    let text = medium_scene(GRID_MEDIUM);
    let err = error_at(&text, "<volume name=\"density\"");
    message_of(
        &err,
        &[
            "<volume type=\"gridvolume\" name=\"density\">",
            "density.vol",
        ],
    );
}

#[test]
fn truncated_vol_file_via_scene() {
    let text = medium_scene(GRID_MEDIUM);
    let (dir, path) = scene_file(&text);
    let grid_path = write_grid(
        dir.path(),
        "density.vol",
        &density_grid([2, 2, 2], unit_bounds()),
    );
    let len = std::fs::metadata(&grid_path).unwrap().len();
    let bytes = std::fs::read(&grid_path).unwrap();
    std::fs::write(&grid_path, &bytes[..len as usize - 3]).unwrap();
    let err = load_mitsuba(&path).unwrap_err();
    message_of(
        &err,
        &[
            &format!("scene.xml:{}:", line_of(&text, "<volume name=\"density\"")),
            "density.vol",
            "32 data bytes",
            "holds 29",
        ],
    );
}

#[test]
fn nan_density_names_the_voxel() {
    let text = medium_scene(GRID_MEDIUM);
    let (dir, path) = scene_file(&text);
    let mut grid = density_grid([2, 2, 2], unit_bounds());
    grid.data[3] = f32::NAN;
    write_grid(dir.path(), "density.vol", &grid);
    let err = load_mitsuba(&path).unwrap_err();
    message_of(
        &err,
        &[
            "scene.xml:",
            "density.vol",
            "voxel (x=1, y=1, z=0)",
            "finite",
            "NaN",
        ],
    );
}

#[test]
fn negative_density_names_the_voxel() {
    let text = medium_scene(GRID_MEDIUM);
    let (dir, path) = scene_file(&text);
    let mut grid = density_grid([2, 2, 2], unit_bounds());
    grid.data[6] = -1.0;
    write_grid(dir.path(), "density.vol", &grid);
    let err = load_mitsuba(&path).unwrap_err();
    message_of(
        &err,
        &[
            "scene.xml:",
            "density.vol",
            "voxel (x=0, y=1, z=1)",
            ">= 0",
            "-1",
        ],
    );
}

#[test]
fn albedo_grid_above_one_is_an_error() {
    let text = medium_scene(
        r#"<medium type="heterogeneous" name="interior">
            <volume name="albedo" type="gridvolume"><string name="filename" value="albedo.vol"/></volume>
        </medium>"#,
    );
    let (dir, path) = scene_file(&text);
    let mut grid = density_grid([2, 2, 2], unit_bounds());
    grid.data[7] = 1.5;
    write_grid(dir.path(), "albedo.vol", &grid);
    let err = load_mitsuba(&path).unwrap_err();
    message_of(&err, &["albedo.vol", "[0, 1]", "voxel (x=1, y=1, z=1)"]);
}

#[test]
fn rotated_grid_is_an_error() {
    let text = medium_scene(
        r#"<medium type="heterogeneous" name="interior">
            <volume name="sigma_t" type="gridvolume">
                <string name="filename" value="density.vol"/>
                <transform name="to_world"><rotate y="1" angle="30"/></transform>
            </volume>
        </medium>"#,
    );
    let (dir, path) = scene_file(&text);
    write_grid(
        dir.path(),
        "density.vol",
        &density_grid([2, 2, 2], unit_bounds()),
    );
    let err = load_mitsuba(&path).unwrap_err();
    message_of(
        &err,
        &[
            &format!("scene.xml:{}:", line_of(&text, "<volume")),
            "gridvolume",
            "axis-aligned",
        ],
    );
}

#[test]
fn unsupported_plugin_names_type_and_line() {
    let text = bsdf_scene(r#"        <bsdf type="plastic"/>"#);
    let err = error_at(&text, "plastic");
    message_of(
        &err,
        &[
            "<bsdf type=\"plastic\">",
            "null, dielectric or roughdielectric",
        ],
    );
}

#[test]
fn unknown_element_is_an_error() {
    let text = bsdf_scene(
        r#"<bsdf type="null"/>
        <frobnicate value="1"/>"#,
    );
    let err = error_at(&text, "<frobnicate");
    message_of(&err, &["<frobnicate>"]);
}

#[test]
fn unknown_parameter_is_only_a_warning() {
    let (_dir, path) = scene_file(&bsdf_scene(
        r#"<bsdf type="dielectric"><float name="colour" value="1"/></bsdf>"#,
    ));
    load_mitsuba(&path).expect("an unknown property is ignored with a warning");
}

#[test]
fn texture_where_a_number_is_needed() {
    let text = bsdf_scene(
        r#"<bsdf type="roughdielectric">
            <string name="distribution" value="ggx"/>
            <texture name="alpha" type="bitmap"/>
        </bsdf>"#,
    );
    let err = error_at(&text, "<texture");
    message_of(
        &err,
        &[
            "<texture type=\"bitmap\" name=\"alpha\">",
            "expected a <float>",
        ],
    );
}

#[test]
fn beckmann_by_default_is_an_error() {
    let text = bsdf_scene(r#"        <bsdf type="roughdielectric"/>"#);
    let err = error_at(&text, "roughdielectric");
    message_of(&err, &["beckmann", "ggx", "distribution"]);
}

#[test]
fn explicit_beckmann_is_an_error() {
    let text = bsdf_scene(
        r#"<bsdf type="roughdielectric">
            <string name="distribution" value="beckmann"/>
        </bsdf>"#,
    );
    let err = error_at(&text, "beckmann");
    message_of(
        &err,
        &["<string name=\"distribution\">", "\"beckmann\"", "ggx"],
    );
}

#[test]
fn anisotropic_roughness_is_an_error() {
    let text = bsdf_scene(
        r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/>
            <float name="alpha_u" value="0.1"/>
            <float name="alpha_v" value="0.2"/>
        </bsdf>"#,
    );
    let err = error_at(&text, "alpha_v");
    message_of(&err, &["<float name=\"alpha_v\">", "isotropic", "\"0.2\""]);
}

#[test]
fn unknown_named_ior_lists_the_names() {
    let text = bsdf_scene(
        r#"<bsdf type="dielectric">
        <string name="int_ior" value="glass"/></bsdf>"#,
    );
    let err = error_at(&text, "int_ior");
    message_of(&err, &["<string name=\"int_ior\">", "bk7", "\"glass\""]);
}

#[test]
fn g_out_of_range() {
    let text = medium_scene(
        r#"<medium type="homogeneous" name="interior">
            <phase type="hg">
                <float name="g" value="1.5"/>
            </phase>
        </medium>"#,
    );
    let err = error_at(&text, "name=\"g\"");
    let line = line_of(&text, "name=\"g\"");
    assert!(err.to_string().ends_with(&format!(
        "scene.xml:{line}: <float name=\"g\">: expected a number in (-1, 1), found \"1.5\""
    )));
}

#[test]
fn non_number_is_named() {
    let text = medium_scene(
        r#"<medium type="homogeneous" name="interior">
            <float name="scale" value="lots"/>
        </medium>"#,
    );
    let err = error_at(&text, "name=\"scale\"");
    message_of(
        &err,
        &["<float name=\"scale\">", "a finite number", "\"lots\""],
    );
}

/// A coloured extinction is a chromatic medium (Mitsuba 3's spelling: an RGB in [0, 1] times
/// `scale`; Mitsuba 0.6's: `sigmaA` + `sigmaS`), and a negative channel is an error.
#[test]
fn coloured_extinction_is_chromatic_and_a_negative_channel_an_error() {
    let text = medium_scene(
        r#"<medium type="homogeneous" name="interior">
            <rgb name="sigma_t" value="0.2, 0.5, 1"/>
            <float name="scale" value="10"/>
        </medium>"#,
    );
    let (_dir, path) = scene_file(&text);
    let desc = load_mitsuba(&path).unwrap();
    assert_eq!(desc.medium.density, DensityDesc::Rgb([0.2, 0.5, 1.0]));
    assert_eq!(desc.medium.scale, 10.0);
    let text = medium_scene(
        r#"<medium type="homogeneous" name="interior">
            <rgb name="sigmaA" value="1, 0, 0"/>
            <rgb name="sigmaS" value="1, 2, 3"/>
        </medium>"#,
    );
    let (_dir, path) = scene_file(&text);
    let desc = load_mitsuba(&path).unwrap();
    assert_eq!(desc.medium.density, DensityDesc::Rgb([2.0, 2.0, 3.0]));
    assert_eq!(desc.medium.albedo, AlbedoDesc::Constant([0.5, 1.0, 1.0]));
    let text = medium_scene(
        r#"<medium type="homogeneous" name="interior">
            <rgb name="sigma_t" value="1, -2, 3"/>
        </medium>"#,
    );
    let err = error_at(&text, "sigma_t");
    message_of(&err, &["<rgb name=\"sigma_t\">", ">= 0", "(1, -2, 3)"]);
}

#[test]
fn density_multiplier_points_to_scale() {
    let text = medium_scene(
        r#"<medium type="heterogeneous" name="interior">
            <float name="densityMultiplier" value="2"/>
        </medium>"#,
    );
    let err = error_at(&text, "densityMultiplier");
    message_of(&err, &["densityMultiplier", "scale"]);
}

#[test]
fn material_preset_in_a_heterogeneous_medium_is_unsupported() {
    let text = medium_scene(
        r#"<medium type="heterogeneous" name="interior">
            <string name="material" value="Ketchup"/>
        </medium>"#,
    );
    let err = error_at(&text, "material");
    message_of(&err, &["<string name=\"material\">", "homogeneous"]);
}

#[test]
fn mitsuba06_heterogeneous_medium_needs_a_density() {
    let text =
        medium_scene(r#"<medium type="heterogeneous" name="interior"/>"#).replace("3.0.0", "0.6.0");
    let err = error_at(&text, "<medium");
    message_of(&err, &["density", "preset"]);
}

#[test]
fn exterior_medium_is_unsupported() {
    let text = medium_scene(
        r#"<medium type="homogeneous" name="interior"/>
        <medium type="homogeneous" name="exterior"/>"#,
    );
    let err = error_at(&text, "exterior");
    message_of(&err, &["name=\"exterior\"", "interior"]);
}

#[test]
fn shape_without_bsdf_explains_why() {
    let text = cube_scene(r#"        <medium type="homogeneous" name="interior"/>"#);
    let err = error_at(&text, "<shape");
    message_of(
        &err,
        &[
            "<shape type=\"cube\">",
            "missing a <bsdf>",
            "null, dielectric or roughdielectric",
        ],
    );
}

#[test]
fn shape_without_medium_is_an_error() {
    let text = cube_scene(r#"        <bsdf type="null"/>"#);
    let err = error_at(&text, "<shape");
    message_of(&err, &["interior medium"]);
}

#[test]
fn rectangle_is_unsupported() {
    let text =
        bsdf_scene(r#"<bsdf type="null"/>"#).replace(r#"type="cube""#, r#"type="rectangle""#);
    let err = error_at(&text, "<shape");
    message_of(&err, &["<shape type=\"rectangle\">", "closed surface"]);
}

#[test]
fn open_obj_is_an_error_naming_its_edge() {
    let text = bsdf_scene(r#"<bsdf type="null"/>"#).replace(
        r#"<shape type="cube">"#,
        "<shape type=\"obj\">\n<string name=\"filename\" value=\"tetra.obj\"/>",
    );
    let (dir, path) = scene_file(&text);
    std::fs::write(
        dir.path().join("tetra.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n",
    )
    .unwrap();
    let err = load_mitsuba(&path).unwrap_err();
    message_of(
        &err,
        &[
            &format!("scene.xml:{}:", line_of(&text, "<shape")),
            "<shape type=\"obj\">",
            "tetra.obj",
            "not closed",
            "edge",
        ],
    );
}

#[test]
fn malformed_obj_vertex_names_obj_line() {
    let text = bsdf_scene(r#"<bsdf type="null"/>"#).replace(
        r#"<shape type="cube">"#,
        "<shape type=\"obj\"><string name=\"filename\" value=\"bad.obj\"/>",
    );
    let (dir, path) = scene_file(&text);
    std::fs::write(dir.path().join("bad.obj"), "# box\nv 0 0 0\nv 1 zero 0\n").unwrap();
    let err = load_mitsuba(&path).unwrap_err();
    message_of(&err, &["scene.xml:", "bad.obj: line 3:", "\"v 1 zero 0\""]);
}

#[test]
fn second_emitter_is_unsupported() {
    let text = bsdf_scene(r#"<bsdf type="null"/>"#).replace(
        "<shape",
        "<emitter type=\"constant\"/>\n    <emitter type=\"constant\"/>\n    <shape",
    );
    let (_dir, path) = scene_file(&text);
    let err = load_mitsuba(&path).unwrap_err();
    let second_line = line_of(&text, "<emitter") + 1;
    message_of(
        &err,
        &[&format!("scene.xml:{second_line}:"), "second emitter"],
    );
}

#[test]
fn emitter_volpt_does_not_have_is_unsupported() {
    let text = bsdf_scene(r#"<bsdf type="null"/>"#).replace(
        "<shape",
        "<emitter type=\"projector\"><float name=\"fov\" value=\"30\"/></emitter>\n<shape",
    );
    let err = error_at(&text, "type=\"projector\"");
    message_of(
        &err,
        &["<emitter type=\"projector\">", "constant", "envmap"],
    );
}

#[test]
fn second_value_for_a_parameter_is_an_error() {
    let text = medium_scene(
        r#"<medium type="homogeneous" name="interior">
            <float name="sigmaT" value="1"/>
            <float name="sigma_t" value="2"/>
        </medium>"#,
    );
    let err = error_at(&text, "name=\"sigma_t\"");
    message_of(&err, &["given once", "first is at line"]);
}

#[test]
fn dangling_ref_names_the_id() {
    let text = cube_scene("        <ref id=\"nothing\"/>");
    let err = error_at(&text, "nothing");
    message_of(&err, &["<ref id=\"nothing\">", "\"nothing\""]);
}

#[test]
fn ref_to_the_wrong_kind_of_object() {
    let text = bsdf_scene(r#"<ref id="forward"/>"#)
        .replace("<shape", "<phase type=\"hg\" id=\"forward\"/>\n    <shape");
    let err = error_at(&text, "<ref");
    message_of(
        &err,
        &[
            "<ref id=\"forward\">",
            "refers to <phase type=\"hg\" id=\"forward\">",
        ],
    );
}

#[test]
fn medium_without_a_name_is_an_error() {
    let text = bsdf_scene(r#"<bsdf type="null"/>"#)
        .replace(r#"name="interior""#, "")
        .replace("<medium", "\n<medium");
    let err = error_at(&text, "<medium");
    message_of(
        &err,
        &[
            "<medium type=\"homogeneous\">",
            "expected name=\"interior\", found no name",
        ],
    );
}

#[test]
fn bad_lookat_is_named() {
    let text = bsdf_scene(r#"<bsdf type="null"/>"#).replace(
        r#"<float name="fov" value="40"/>"#,
        "<transform name=\"to_world\">\n<lookat origin=\"0, 0, 1\" target=\"0, 0, 1\" up=\"0, 1, 0\"/></transform>",
    );
    let err = error_at(&text, "<lookat");
    message_of(&err, &["<lookat target>", "different from the origin"]);
}

/// The limits of values that may be zero but not negative sit exactly at zero: a black
/// environment and a zero medium scale load, a negative scale and a zero focal length do not.
#[test]
fn zero_is_the_edge_of_non_negative_and_positive_values() {
    let black = cube_scene(
        "        <bsdf type=\"null\"/>\n        <medium type=\"homogeneous\" name=\"interior\"/>",
    )
    .replace(
        "</scene>",
        "<emitter type=\"constant\"><rgb name=\"radiance\" value=\"0\"/></emitter>\n</scene>",
    );
    let (_dir, path) = scene_file(&black);
    load_mitsuba(&path).expect("a black environment loads");
    let scaled = |scale: &str| {
        medium_scene(&format!(
            "<medium type=\"homogeneous\" name=\"interior\"><float name=\"scale\" value=\"{scale}\"/></medium>"
        ))
    };
    let (_dir, path) = scene_file(&scaled("0"));
    load_mitsuba(&path).expect("scale 0 loads");
    let err = error_at(&scaled("-1"), "name=\"scale\"");
    message_of(&err, &["scale", ">= 0"]);
    let focal = cube_scene("        <bsdf type=\"null\"/>").replace(
        "<float name=\"fov\" value=\"40\"/>",
        "<string name=\"focal_length\" value=\"0mm\"/>",
    );
    let err = error_at(&focal, "focal_length");
    message_of(&err, &["focal_length", "positive length"]);
}

/// `<srgb>` decodes the sRGB curve's linear toe (values <= 0.04045 divide by 12.92) as well as its
/// power segment.
#[test]
fn srgb_decodes_the_linear_toe_and_the_power_curve() {
    let (_dir, path) = scene_file(&medium_scene(
        r#"<medium type="homogeneous" name="interior"><srgb name="albedo" value="0.02, 0.5, 1"/></medium>"#,
    ));
    let scene = load_mitsuba(&path).expect("scene loads");
    let volpt_scene::AlbedoDesc::Constant(rgb) = scene.medium.albedo else {
        panic!(
            "expected a constant albedo, found {:?}",
            scene.medium.albedo
        );
    };
    let expected = [0.02 / 12.92, ((0.5f64 + 0.055) / 1.055).powf(2.4), 1.0];
    for (got, want) in rgb.iter().zip(expected) {
        assert!((*got as f64 - want).abs() < 1e-6, "{rgb:?} vs {expected:?}");
    }
}

/// Character data the loader cannot use is an error at its line, as is invalid UTF-8 (at the line
/// of the first bad byte).
#[test]
fn cdata_and_invalid_utf8_are_errors_at_their_lines() {
    let text = cube_scene("        <bsdf type=\"null\"/>")
        .replace("<shape", "<![CDATA[ stray text ]]>\n    <shape");
    let err = error_at(&text, "CDATA");
    message_of(&err, &["CDATA"]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.xml");
    let mut bytes =
        b"<scene version=\"3.0.0\">\n<!-- line 2 -->\n<!-- \xff -->\n</scene>\n".to_vec();
    bytes.shrink_to_fit();
    std::fs::write(&path, &bytes).unwrap();
    let err = load_mitsuba(&path).expect_err("invalid UTF-8 is an error");
    message_of(&err, &["scene.xml:3"]);
}

/// A long quoted value is cut at a character boundary at or below the limit, never inside a
/// multi-byte character.
#[test]
fn excerpt_cuts_long_text_at_a_character_boundary() {
    use volpt_scene::error::{excerpt, MAX_QUOTED_BYTES};
    let text = format!("a{}", "é".repeat(150));
    assert_eq!(text.len(), 301);
    assert!(!text.is_char_boundary(MAX_QUOTED_BYTES));
    let cut = excerpt(&text);
    assert_eq!(cut, format!("a{}... (301 bytes in all)", "é".repeat(99)));
    assert_eq!(excerpt("short"), "short");
}
