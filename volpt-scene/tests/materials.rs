//! Material-indexed volumes in TOML scenes (`[[materials]]` with an index grid or a PNG slice
//! stack) and Mitsuba 0.6's `material` presets: what they load to, and one clear error, naming
//! the file, the field or voxel, what was expected and what was found, per kind of mistake.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use volpt_scene::description::PhaseDesc;
use volpt_scene::error::MaterialProblem;
use volpt_scene::{builder_for, AlbedoDesc, Config, DensityDesc, SceneAssembler, SceneError};

/// The memory limit is global: the test that lowers it runs alone.
static LIMIT: Mutex<()> = Mutex::new(());

const MATERIALS: &str = r##"
[[materials]]
name = "cyan"
sigma_s = [4.0, 6.0, 7.0]
sigma_a = [6.0, 0.8, 0.2]
g = 0.3
colour = [0, 255, 255]
[[materials]]
name = "white"
sigma_t = 12.0
albedo = [0.99, 0.98, 0.97]
colour = "#ffffff"
"##;

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("write fixture");
    path
}

/// A 3x2x2 `u8` index grid and a scene of it; `extra` follows the volume's keys.
fn raw_scene(indices: &[u8], extra: &str, materials: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("temp dir");
    write(dir.path(), "print.raw", indices);
    let text = format!(
        "[volume]\nfile = \"print.raw\"\nformat = \"raw\"\nresolution = [3, 2, 2]\ntype = \"u8\"\n\
         bounds = [[0.0, 0.0, 0.0], [3.0, 2.0, 2.0]]\n{extra}\n{materials}"
    );
    let path = write(dir.path(), "scene.toml", text.as_bytes());
    (dir, path)
}

fn load(path: &Path) -> Result<volpt_scene::SceneDescription, SceneError> {
    let _guard = LIMIT.lock().unwrap_or_else(|e| e.into_inner());
    SceneAssembler::new(Config::default()).assemble(builder_for(path)?.as_ref())
}

const PRINT: [u8; 12] = [0, 1, 1, 0, 0, 1, 1, 1, 0, 0, 0, 1];

#[test]
fn a_raw_index_grid_and_its_table_load_as_an_indexed_medium() {
    let (_dir, path) = raw_scene(&PRINT, "scale = 2.0", MATERIALS);
    let desc = load(&path).unwrap();
    let DensityDesc::Indexed(indexed) = &desc.medium.density else {
        panic!(
            "an indexed medium expected, found {:?}",
            desc.medium.density
        )
    };
    assert_eq!(indexed.resolution, [3, 2, 2]);
    assert_eq!(
        (0..12).map(|i| indexed.index(i)).collect::<Vec<_>>(),
        PRINT.map(u32::from)
    );
    let white = &indexed.materials()[1];
    // sigma_t and albedo spell sigma_s = albedo * sigma_t and the rest absorbed.
    assert_eq!(white.sigma_s, [0.99 * 12.0, 0.98 * 12.0, 0.97 * 12.0]);
    assert_eq!(white.colour, Some([255, 255, 255]));
    assert_eq!(indexed.histogram(), vec![6, 6]);
    // The materials' g differ from 0: a Henyey-Greenstein variant (with the first non-zero g,
    // which the factory does not specialise to the isotropic phase), g per collision.
    assert_eq!(desc.medium.phase, PhaseDesc::HenyeyGreenstein { g: 0.3 });
    assert_eq!(desc.medium.scale, 2.0);
    assert!(desc.medium.is_chromatic());
    // Largest extinction: white's 12, times the scale.
    assert_eq!(desc.medium.max_extinction(), 24.0);
    // `volpt info`'s density line prints the table and the GPU memory (12 bytes of indices and
    // 2 rows of 8 floats).
    let info = desc.medium.density.to_string();
    assert!(info.contains("2 materials"), "{info}");
    assert!(info.contains("GPU memory 76 bytes"), "{info}");
    assert!(info.contains("cyan") && info.contains("voxels 6"), "{info}");
}

#[test]
fn an_index_outside_the_table_is_refused_with_its_voxel() {
    let mut indices = PRINT;
    indices[7] = 2;
    let (_dir, path) = raw_scene(&indices, "", MATERIALS);
    let err = load(&path).unwrap_err();
    assert!(
        matches!(
            &err,
            SceneError::Material {
                problem: MaterialProblem::IndexOutOfTable {
                    voxel: [1, 0, 1],
                    index: 2,
                    materials: 2
                },
                ..
            }
        ),
        "{err:?}"
    );
    let message = err.to_string();
    assert!(
        message.contains("print.raw") && message.contains("below 2"),
        "{message}"
    );
}

#[test]
fn a_value_that_is_no_index_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let values: Vec<u8> = [0.0f32, 1.0, 1.5, 0.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    write(dir.path(), "print.raw", &values);
    let text = format!(
        "[volume]\nfile = \"print.raw\"\nformat = \"raw\"\nresolution = [2, 2, 1]\ntype = \"f32\"\n\
         bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]\n{MATERIALS}"
    );
    let path = write(dir.path(), "scene.toml", text.as_bytes());
    let err = load(&path).unwrap_err();
    assert!(
        matches!(
            &err,
            SceneError::Material {
                problem: MaterialProblem::NotAnIndex {
                    voxel: [0, 1, 0],
                    ..
                },
                ..
            }
        ),
        "{err:?}"
    );
}

/// `n` materials, material `k` of extinction `k + 1` and colour `(k / 256, k % 256, 7)`.
fn many_materials(n: usize) -> String {
    (0..n)
        .map(|k| {
            format!(
                "[[materials]]\nname = \"m{k}\"\nsigma_s = {}\nsigma_a = 0.5\ncolour = [{}, {}, 7]\n",
                k as f32 + 0.5,
                k / 256,
                k % 256
            )
        })
        .collect()
}

/// Indices of a table of more than 256 materials: 16 bits a voxel, past 255.
const WIDE_PRINT: [u16; 12] = [0, 299, 256, 255, 1, 298, 257, 0, 128, 299, 200, 3];

/// Beyond 256 materials (a print of many mixtures) the indices are 16 bits: a raw `u16` grid and
/// a PNG slice stack whose palette names 300 materials load, each voxel's index read back, the
/// core's grid reads each voxel's material (its extinction at the voxel's centre), and the GPU
/// memory counts two bytes a voxel.
#[test]
fn a_table_of_more_than_256_materials_has_16_bit_indices() {
    let materials = many_materials(300);
    let dir = tempfile::tempdir().unwrap();
    let bytes: Vec<u8> = WIDE_PRINT.iter().flat_map(|k| k.to_le_bytes()).collect();
    write(dir.path(), "print.raw", &bytes);
    let text = format!(
        "[volume]\nfile = \"print.raw\"\nformat = \"raw\"\nresolution = [3, 2, 2]\ntype = \"u16\"\n\
         bounds = [[0.0, 0.0, 0.0], [3.0, 2.0, 2.0]]\n{materials}"
    );
    let raw = write(dir.path(), "scene.toml", text.as_bytes());
    let layers = dir.path().join("layers");
    std::fs::create_dir(&layers).unwrap();
    for z in 0..2u32 {
        png(&layers.join(format!("layer{z}.png")), 3, 2, |x, y| {
            let k = WIDE_PRINT[(z * 6 + y * 3 + x) as usize];
            [(k / 256) as u8, (k % 256) as u8, 7]
        });
    }
    let text = format!(
        "[volume]\nfile = \"layers\"\nbounds = [[0.0, 0.0, 0.0], [3.0, 2.0, 2.0]]\n{materials}"
    );
    let slices = write(dir.path(), "slices.toml", text.as_bytes());
    for path in [raw, slices] {
        let desc = load(&path).unwrap();
        let DensityDesc::Indexed(indexed) = &desc.medium.density else {
            panic!("an indexed medium expected")
        };
        assert_eq!(
            (0..12).map(|i| indexed.index(i)).collect::<Vec<_>>(),
            WIDE_PRINT.map(u32::from),
            "{}",
            path.display()
        );
        assert_eq!(indexed.packed_indices().len(), 6);
        assert_eq!(indexed.device_bytes(), 6 * 4 + 300 * 32);
        let grid = volpt_core::MaterialGrid::new(
            indexed.packed_indices(),
            indexed.resolution,
            volpt_core::Aabb::new(volpt_core::Vec3::ZERO, volpt_core::Vec3::new(3.0, 2.0, 2.0)),
            indexed.table(),
            1.0,
        );
        for (i, &k) in WIDE_PRINT.iter().enumerate() {
            let (x, y, z) = (i % 3, i / 3 % 2, i / 6);
            let centre = volpt_core::Vec3::new(x as f32 + 0.5, y as f32 + 0.5, z as f32 + 0.5);
            assert_eq!(
                grid.sigma_t(centre),
                volpt_core::Spectrum::splat(k as f32 + 1.0)
            );
        }
        assert_eq!(grid.max_extinction(), 300.0);
    }
}

#[test]
fn a_table_of_more_than_65536_materials_is_refused() {
    let material = volpt_scene::material::MaterialDesc {
        name: String::new(),
        sigma_s: [1.0; 3],
        sigma_a: [0.5; 3],
        g: 0.0,
        colour: None,
    };
    let err = volpt_scene::material::IndexedDesc::new(
        Path::new("print.raw"),
        vec![material; 65537],
        [3, 2, 2],
        volpt_scene::description::Bounds {
            min: [0.0; 3],
            max: [3.0, 2.0, 2.0],
        },
        &PRINT,
    )
    .unwrap_err();
    assert!(
        matches!(
            &err,
            SceneError::Material {
                problem: MaterialProblem::TableSize { found: 65537 },
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("1 to 65536 materials"), "{err}");
}

#[test]
fn bad_coefficients_name_their_material_and_field() {
    for (materials, field) in [
        (
            "[[materials]]\nname = \"a\"\nsigma_s = -1.0\nsigma_a = 0.5\n",
            "materials[0].sigma_s",
        ),
        (
            "[[materials]]\nname = \"a\"\nsigma_s = 1.0\nsigma_a = nan\n",
            "materials[0].sigma_a",
        ),
        (
            "[[materials]]\nname = \"a\"\nsigma_s = 1.0\nsigma_a = 1.0\ng = 1.0\n",
            "materials[0].g",
        ),
        (
            "[[materials]]\nname = \"a\"\nsigma_t = 1.0\nalbedo = 1.5\n",
            "materials[0].albedo",
        ),
        (
            "[[materials]]\nname = \"a\"\nsigma_s = 1.0\n",
            "materials[0]",
        ),
    ] {
        let (_dir, path) = raw_scene(&[0; 12], "", materials);
        let err = load(&path).unwrap_err();
        let message = err.to_string();
        assert!(
            matches!(&err, SceneError::InvalidValue { field: f, .. } if f == field),
            "{field}: {message}"
        );
    }
}

#[test]
fn an_albedo_or_phase_beside_materials_is_refused() {
    for extra in ["[albedo]\nvalue = 0.5\n", "[phase]\ng = 0.5\n"] {
        let (_dir, path) = raw_scene(&PRINT, "", &format!("{extra}{MATERIALS}"));
        let message = load(&path).unwrap_err().to_string();
        assert!(message.contains("[[materials]]"), "{message}");
    }
}

/// A PNG of `w x h` pixels of colour `colour(x, y)`.
fn png(path: &Path, w: u32, h: u32, colour: impl Fn(u32, u32) -> [u8; 3]) {
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().unwrap();
    let data: Vec<u8> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .flat_map(|(x, y)| colour(x, y))
        .collect();
    writer.write_image_data(&data).unwrap();
}

const CYAN: [u8; 3] = [0, 255, 255];
const WHITE: [u8; 3] = [255, 255, 255];

/// The slices of [`PRINT`] (3 x 2 pixels, 2 layers), plus `extra` slices.
fn slices_scene(volume: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let slices = dir.path().join("layers");
    std::fs::create_dir(&slices).unwrap();
    for z in 0..2u32 {
        png(
            &slices.join(format!("layer{z}.png")),
            3,
            2,
            |x, y| match PRINT[(z * 6 + y * 3 + x) as usize] {
                0 => CYAN,
                _ => WHITE,
            },
        );
    }
    let text = format!("[volume]\nfile = \"layers\"\n{volume}\n{MATERIALS}");
    let path = write(dir.path(), "scene.toml", text.as_bytes());
    (dir, path)
}

#[test]
fn a_png_slice_stack_loads_as_its_raw_index_grid() {
    let (_dir, path) = slices_scene("voxel_size = [1.0, 1.0, 1.0]");
    let desc = load(&path).unwrap();
    let DensityDesc::Indexed(indexed) = &desc.medium.density else {
        panic!("an indexed medium expected")
    };
    assert_eq!(indexed.resolution, [3, 2, 2]);
    assert_eq!(
        (0..12).map(|i| indexed.index(i)).collect::<Vec<_>>(),
        PRINT.map(u32::from)
    );
    // The box is centred on the origin, one unit a voxel.
    assert_eq!(indexed.bounds.min, [-1.5, -1.0, -1.0]);
    assert_eq!(desc.boundary.bounds.max, [1.5, 1.0, 1.0]);
    assert_eq!(desc.medium.albedo, AlbedoDesc::Constant([0.0; 3]));
}

#[test]
fn slices_of_another_size_a_stray_colour_or_a_missing_slice_are_refused() {
    // A slice of another size.
    let (dir, path) = slices_scene("voxel_size = [1.0, 1.0, 1.0]");
    png(&dir.path().join("layers/layer2.png"), 4, 2, |_, _| WHITE);
    let err = load(&path).unwrap_err();
    assert!(
        matches!(
            &err,
            SceneError::Material {
                problem: MaterialProblem::SliceSize {
                    expected: [3, 2],
                    found: [4, 2],
                    ..
                },
                ..
            }
        ),
        "{err:?}"
    );
    // A colour the palette does not name.
    let (dir, path) = slices_scene("voxel_size = [1.0, 1.0, 1.0]");
    png(&dir.path().join("layers/layer1.png"), 3, 2, |x, _| {
        if x == 2 {
            [10, 20, 30]
        } else {
            WHITE
        }
    });
    let err = load(&path).unwrap_err();
    assert!(
        matches!(
            &err,
            SceneError::Material {
                problem: MaterialProblem::PaletteColour {
                    pixel: [2, 0],
                    colour: [10, 20, 30],
                    ..
                },
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("#0a141e"), "{err}");
    // A missing slice: the scene says three layers.
    let (_dir, path) = slices_scene("voxel_size = [1.0, 1.0, 1.0]\nresolution = [3, 2, 3]");
    let err = load(&path).unwrap_err();
    assert!(
        matches!(
            &err,
            SceneError::Material {
                problem: MaterialProblem::SliceCount {
                    expected: 3,
                    found: 2,
                    ..
                },
                ..
            }
        ),
        "{err:?}"
    );
}

#[test]
fn a_slice_stack_over_the_memory_limit_is_refused_before_decoding() {
    let (_dir, path) = slices_scene("voxel_size = [1.0, 1.0, 1.0]");
    let _guard = LIMIT.lock().unwrap_or_else(|e| e.into_inner());
    let before = volpt_scene::limits::memory_limit();
    // The scene file (under 1 KB) fits; the 12 indices do not.
    volpt_scene::limits::set_memory_limit(11);
    let result =
        SceneAssembler::new(Config::default()).assemble(builder_for(&path).unwrap().as_ref());
    volpt_scene::limits::set_memory_limit(before);
    let err = result.unwrap_err();
    assert!(matches!(err, SceneError::OverMemoryLimit { .. }), "{err:?}");
}

fn mitsuba(medium: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        r#"<scene version="0.6.0">
    <integrator type="volpath"/>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="toWorld"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="cube">
        <bsdf type="null"/>
        <medium type="homogeneous" name="interior">{medium}</medium>
    </shape>
</scene>"#
    );
    let path = write(dir.path(), "scene.xml", text.as_bytes());
    (dir, path)
}

#[test]
fn mitsuba_presets_give_the_tables_coefficients_times_100_and_the_scale() {
    let (_dir, path) =
        mitsuba(r#"<string name="material" value="ketchup"/><float name="scale" value="0.01"/>"#);
    let desc = load(&path).unwrap();
    // Ketchup: sigmaS (0.18, 0.07, 0.03), sigmaA (0.061, 0.97, 1.45) per mm, x 100.
    let t = [0.18f32 * 100.0 + 0.061 * 100.0, 7.0 + 97.0, 3.0 + 145.0];
    let DensityDesc::Rgb(rgb) = desc.medium.density else {
        panic!(
            "a chromatic extinction expected, found {:?}",
            desc.medium.density
        )
    };
    for c in 0..3 {
        assert!((rgb[c] - t[c]).abs() <= 1e-4 * t[c], "{rgb:?} vs {t:?}");
    }
    assert_eq!(desc.medium.scale, 0.01);
    let AlbedoDesc::Constant(albedo) = desc.medium.albedo else {
        panic!("constant albedo")
    };
    assert!((albedo[0] - 18.0 / 24.1).abs() < 1e-5, "{albedo:?}");
    // Mitsuba 0.6's default is Skin1.
    let (_dir, path) = mitsuba("");
    let desc = load(&path).unwrap();
    assert!(matches!(desc.medium.density, DensityDesc::Rgb(_)));
}

#[test]
fn an_unknown_preset_or_a_preset_with_coefficients_is_refused() {
    let (_dir, path) = mitsuba(r#"<string name="material" value="jam"/>"#);
    let message = load(&path).unwrap_err().to_string();
    assert!(
        message.contains("Skin1") && message.contains("jam"),
        "{message}"
    );
    let (_dir, path) =
        mitsuba(r#"<string name="material" value="skin1"/><rgb name="sigmaA" value="1, 1, 1"/>"#);
    let message = load(&path).unwrap_err().to_string();
    assert!(message.contains("preset"), "{message}");
}

/// The materials' coefficients are parameters named by the material's name (or its index): listed
/// with what each is, read, set (the phase variant follows the `g`s), and a bad value or an
/// unknown material refused with the table left as it was.
#[test]
fn materials_coefficients_are_parameters_by_name_or_index() {
    use volpt_scene::medium::{MediumParam, ParamRefused};
    let (_dir, path) = raw_scene(&PRINT, "", MATERIALS);
    let mut desc = load(&path).unwrap();
    let medium = &mut desc.medium;
    let keys: Vec<String> = medium
        .material_params()
        .into_iter()
        .map(|(k, _)| k)
        .collect();
    assert_eq!(
        keys,
        [
            "materials.cyan.sigma_s",
            "materials.cyan.sigma_a",
            "materials.cyan.g",
            "materials.white.sigma_s",
            "materials.white.sigma_a",
            "materials.white.g",
        ]
    );
    assert_eq!(
        medium.param("materials.cyan.sigma_a"),
        Some(Ok(MediumParam::Rgb([6.0, 0.8, 0.2])))
    );
    // The index names the same material.
    assert_eq!(
        medium.param("materials.0.sigma_a"),
        medium.param("materials.cyan.sigma_a")
    );
    let set = |m: &mut volpt_scene::MediumDesc, key: &str, v| m.set_param(key, v);
    assert_eq!(
        set(
            medium,
            "materials.white.sigma_a",
            MediumParam::Rgb([1.0, 2.0, 3.0])
        ),
        Some(Ok(()))
    );
    assert_eq!(
        medium.param("materials.1.sigma_a"),
        Some(Ok(MediumParam::Rgb([1.0, 2.0, 3.0])))
    );
    // Every g 0: the isotropic phase; one non-zero: Henyey-Greenstein with it.
    set(medium, "materials.cyan.g", MediumParam::Float(0.0));
    assert_eq!(medium.phase, PhaseDesc::Isotropic);
    set(medium, "materials.white.g", MediumParam::Float(-0.4));
    assert_eq!(medium.phase, PhaseDesc::HenyeyGreenstein { g: -0.4 });
    let before = medium.clone();
    for (key, value) in [
        ("materials.cyan.sigma_s", MediumParam::Rgb([-1.0, 0.0, 0.0])),
        (
            "materials.cyan.sigma_s",
            MediumParam::Rgb([f32::NAN, 0.0, 0.0]),
        ),
        ("materials.cyan.g", MediumParam::Float(1.0)),
        ("materials.cyan.g", MediumParam::Rgb([0.1, 0.1, 0.1])),
    ] {
        assert!(
            matches!(set(medium, key, value), Some(Err(ParamRefused::Value(_)))),
            "{key} = {value:?}"
        );
    }
    for key in ["materials.magenta.g", "materials.2.g"] {
        assert!(
            matches!(
                set(medium, key, MediumParam::Float(0.1)),
                Some(Err(ParamRefused::NotHere { .. }))
            ),
            "{key}"
        );
    }
    assert_eq!(
        format!("{:?}", medium),
        format!("{before:?}"),
        "a refusal changes nothing"
    );
}
