//! Slice stacks: exact round trips over random prints, and every kind of bad stack refused with
//! an error naming the file, what was expected and what was found.

mod common;

use std::path::Path;

use common::{inks, Rng};
use volpt_print::slices::{read_slices, slice_name, write_slices, MATERIALS_FILE};
use volpt_print::{MaterialDesc, PrintError, VoxelPrint};
use volpt_scene::{MaterialProblem, SceneError};

fn random_print(rng: &mut Rng) -> VoxelPrint {
    let count = 1 + rng.below(7) as usize;
    let mut materials: Vec<MaterialDesc> = Vec::new();
    while materials.len() < count {
        let colour = [0, 1, 2].map(|_| rng.below(256) as u8);
        if materials.iter().all(|m| m.colour != Some(colour)) {
            materials.push(MaterialDesc {
                name: format!("m{}", materials.len()),
                colour: Some(colour),
                sigma_s: [rng.unit() as f32 * 5.0; 3],
                sigma_a: [0.5, 1.0, rng.unit() as f32],
                g: 0.25,
            });
        }
    }
    let resolution = [1 + rng.below(9), 1 + rng.below(9), 1 + rng.below(12)].map(|n| n as u32);
    let voxels = resolution.iter().product::<u32>() as usize;
    let indices = (0..voxels).map(|_| rng.below(count as u64) as u8).collect();
    let voxel_size = [0.0846, 0.0423, 0.027 * (1.0 + rng.unit())];
    VoxelPrint::new(materials, voxel_size, resolution, indices).unwrap()
}

#[test]
fn random_prints_round_trip_exactly() {
    let mut rng = Rng(40);
    for case in 0..40 {
        let print = random_print(&mut rng);
        let dir = tempfile::tempdir().unwrap();
        write_slices(&print, dir.path()).unwrap();
        let back = read_slices(dir.path()).unwrap();
        assert_eq!(back, print, "case {case}");
    }
}

#[test]
fn slice_names_have_four_digits_or_as_many_as_the_last_needs() {
    assert_eq!(slice_name(0, 1), "slice_0000.png");
    assert_eq!(slice_name(99, 100), "slice_0099.png");
    assert_eq!(slice_name(9999, 10000), "slice_9999.png");
    assert_eq!(slice_name(7, 10001), "slice_00007.png");
}

/// A written 5 x 4 x 3 stack of the five inks.
fn stack(dir: &Path) -> VoxelPrint {
    let indices = (0..60).map(|i| (i % 5) as u8).collect();
    let print = VoxelPrint::new(inks(), [0.1, 0.1, 0.05], [5, 4, 3], indices).unwrap();
    write_slices(&print, dir).unwrap();
    print
}

fn write_png(path: &Path, [w, h]: [u32; 2], rgb: &[u8]) {
    let file = std::fs::File::create(path).unwrap();
    let mut e = png::Encoder::new(file, w, h);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(png::BitDepth::Eight);
    e.write_header().unwrap().write_image_data(rgb).unwrap();
}

fn message(e: PrintError) -> String {
    e.to_string()
}

#[test]
fn a_colour_outside_the_palette_is_refused_naming_slice_and_pixel() {
    let dir = tempfile::tempdir().unwrap();
    stack(dir.path());
    let mut rgb = vec![255u8; 5 * 4 * 3];
    // Pixel (2, 1) of a 5-wide slice.
    let at = 3 * (2 + 5);
    rgb[at..at + 3].copy_from_slice(&[1, 2, 3]);
    let slice = dir.path().join("slice_0001.png");
    write_png(&slice, [5, 4], &rgb);
    let e = read_slices(dir.path()).unwrap_err();
    assert!(
        matches!(&e, PrintError::Scene(SceneError::Material {
            path,
            problem: MaterialProblem::PaletteColour { slice: name, pixel: [2, 1], colour: [1, 2, 3], .. },
        }) if *path == slice && name == "slice_0001.png"),
        "{e:?}"
    );
    let m = message(e);
    assert!(
        m.contains("slice_0001.png") && m.contains("#010203") && m.contains("#00ffff cyan"),
        "{m}"
    );
}

#[test]
fn a_slice_of_another_size_is_refused_before_any_pixel_is_decoded() {
    let dir = tempfile::tempdir().unwrap();
    stack(dir.path());
    let slice = dir.path().join("slice_0002.png");
    // Its pixels are outside the palette too: the size is refused first.
    write_png(&slice, [6, 4], &[7u8; 6 * 4 * 3]);
    let e = read_slices(dir.path()).unwrap_err();
    assert!(
        matches!(&e, PrintError::Scene(SceneError::Material {
            problem: MaterialProblem::SliceSize { slice: name, expected: [5, 4], found: [6, 4], .. },
            ..
        }) if name == "slice_0002.png"),
        "{e:?}"
    );
    assert!(message(e).contains("expected 5x4 pixels (materials.toml's width, height and layers)"));
    // The first slice is held to materials.toml's size too, not to the others'.
    let slice = dir.path().join("slice_0000.png");
    write_png(&slice, [5, 3], &[7u8; 5 * 3 * 3]);
    let e = read_slices(dir.path()).unwrap_err();
    assert!(
        matches!(&e, PrintError::Scene(SceneError::Material {
            problem: MaterialProblem::SliceSize { slice: name, expected: [5, 4], found: [5, 3], .. },
            ..
        }) if name == "slice_0000.png"),
        "{e:?}"
    );
}

#[test]
fn a_missing_slice_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    stack(dir.path());
    std::fs::remove_file(dir.path().join("slice_0001.png")).unwrap();
    let m = message(read_slices(dir.path()).unwrap_err());
    assert!(
        m.contains("no slice_0001.png") && m.contains("3 slices slice_0000.png .. slice_0002.png"),
        "{m}"
    );
    // The last one missing is a gap too (`layers` says how many).
    let dir = tempfile::tempdir().unwrap();
    stack(dir.path());
    std::fs::remove_file(dir.path().join("slice_0002.png")).unwrap();
    assert!(message(read_slices(dir.path()).unwrap_err()).contains("no slice_0002.png"));
}

#[test]
fn an_extra_or_misspelt_slice_is_refused_by_name() {
    for extra in ["slice_0003.png", "slice_1.png", "slice_00001.png"] {
        let dir = tempfile::tempdir().unwrap();
        stack(dir.path());
        std::fs::copy(dir.path().join("slice_0000.png"), dir.path().join(extra)).unwrap();
        let e = read_slices(dir.path()).unwrap_err();
        assert!(matches!(e, PrintError::SliceNumbering { .. }), "{e:?}");
        assert!(message(e).contains(&format!("an extra slice {extra}")));
    }
}

#[test]
fn a_slice_that_is_not_a_regular_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    stack(dir.path());
    let slice = dir.path().join("slice_0000.png");
    std::fs::remove_file(&slice).unwrap();
    std::fs::create_dir(&slice).unwrap();
    let m = message(read_slices(dir.path()).unwrap_err());
    assert!(
        m.contains("slice_0000.png") && m.contains("directory"),
        "{m}"
    );
}

fn rewrite_toml(dir: &Path, edit: impl Fn(String) -> String) {
    let path = dir.join(MATERIALS_FILE);
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, edit(text)).unwrap();
}

#[test]
fn bad_material_tables_are_refused_naming_the_field() {
    let cases: [(&str, &str, &str); 4] = [
        ("sigma_a = [3.0", "sigma_a = [-3.0", "materials[0].sigma_a"),
        ("g = 0.0", "g = 1.0", "materials[0].g"),
        (
            "colour = [255, 0, 255]",
            "colour = [0, 255, 255]",
            "a palette colour per material",
        ),
        ("layers = 3", "layers = 0", "each at least 1"),
    ];
    for (from, to, expected) in cases {
        let dir = tempfile::tempdir().unwrap();
        stack(dir.path());
        rewrite_toml(dir.path(), |t| {
            assert!(t.contains(from), "{t}");
            t.replacen(from, to, 1)
        });
        let m = message(read_slices(dir.path()).unwrap_err());
        assert!(
            m.contains("materials.toml") && m.contains(expected),
            "{from} -> {to}: {m}"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    stack(dir.path());
    rewrite_toml(dir.path(), |t| t + "\nbogus = 1\n");
    let m = message(read_slices(dir.path()).unwrap_err());
    assert!(m.contains("bogus"), "{m}");
}

#[test]
fn writing_over_a_stack_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let print = stack(dir.path());
    let m = message(write_slices(&print, dir.path()).unwrap_err());
    assert!(
        m.contains("a folder without slice_*.png or materials.toml"),
        "{m}"
    );
}
