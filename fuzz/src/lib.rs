//! Fuzz targets for every parser of volpt's scene inputs (issue 12), its film files and the
//! viewer's messages (issue 43), shared by two drivers:
//!
//! - `cargo test -p volpt-fuzz` runs every target on its seeds and a few thousand deterministic
//!   mutations of them (stable Rust, no tools, seconds): CI's short run.
//! - `fuzz/run TARGET SECONDS` builds the targets with libFuzzer's coverage instrumentation (on
//!   stable rustc) and fuzzes one for real, seeded from [`seeds`], under a 2 GB memory limit and
//!   a per-input timeout (`docs/reliability.md`).
//!
//! A target turns the fuzzer's bytes into files (several files are split at [`SPLIT`]), loads
//! them the way `volpt` does, and returns; any error is fine, a panic, abort, hang or huge
//! allocation is a bug. Loaded scenes go through the [`SceneAssembler`], so validation runs too.

use std::path::{Path, PathBuf};
use std::sync::Once;

use volpt_scene::{
    builder_for, Bounds, Config, GridConvention, GridDesc, MetaImageOptions, SceneAssembler,
    TransferFunction,
};

/// Separates the files of a multi-file input.
pub const SPLIT: &[u8] = b"\n@@@\n";

/// The memory limit while fuzzing: a quarter of the 2 GB the fuzzer allows a process, so that
/// what the limit admits (plus a decoder's temporary copies) fits.
pub const FUZZ_MEMORY_LIMIT: u64 = 256 << 20;

/// One parser, or one way into the scene loader.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// Mitsuba XML: `scene.xml`, an included `inc.xml`, and `name=value` parameter lines.
    MitsubaXml,
    /// A bare `.vol` grid, as `volpt render grid.vol` loads it.
    Vol,
    /// MetaImage: one `.mha`, or a `.mhd` header and its data file `d.raw`.
    MetaImage,
    /// Legacy VTK (`.vtk`).
    VtkLegacy,
    /// VTK XML image data (`.vti`).
    VtkXml,
    /// A volpt TOML scene with a raw grid `g.raw` and a transfer function `t.tf`.
    TomlRaw,
    /// A transfer-function file, applied to a small grid.
    TransferFunction,
    /// An OpenEXR environment map under a fixed scene.
    ExrEnvmap,
    /// A bare OpenVDB `.vdb` grid, as `volpt render cloud.vdb` loads it.
    Vdb,
    /// NRRD: one `.nrrd`, or a `.nhdr` header and its data file `d.raw`.
    Nrrd,
    /// A TIFF stack: one multi-page `.tif`, or a folder of TIFFs (one per part), as
    /// `volpt render stack.tif` or `volpt render FOLDER` loads it.
    TiffStack,
    /// A folder of DICOM slices (one per part), as `volpt render FOLDER` loads it.
    DicomSeries,
    /// A film file (or checkpoint), read and merged as `volpt merge` does.
    FilmFile,
    /// One text message of the viewer's WebSocket protocol, parsed and applied to a scene as the
    /// viewer's render thread applies it.
    ViewerMessage,
}

impl Target {
    pub const ALL: [Target; 14] = [
        Self::MitsubaXml,
        Self::Vol,
        Self::MetaImage,
        Self::VtkLegacy,
        Self::VtkXml,
        Self::TomlRaw,
        Self::TransferFunction,
        Self::ExrEnvmap,
        Self::Vdb,
        Self::Nrrd,
        Self::TiffStack,
        Self::DicomSeries,
        Self::FilmFile,
        Self::ViewerMessage,
    ];

    /// The name `fuzz/run` knows the target by.
    pub fn name(self) -> &'static str {
        match self {
            Self::MitsubaXml => "mitsuba_xml",
            Self::Vol => "vol",
            Self::MetaImage => "metaimage",
            Self::VtkLegacy => "vtk_legacy",
            Self::VtkXml => "vtk_xml",
            Self::TomlRaw => "toml_raw",
            Self::TransferFunction => "transfer_function",
            Self::ExrEnvmap => "exr_envmap",
            Self::Vdb => "vdb",
            Self::Nrrd => "nrrd",
            Self::TiffStack => "tiff_stack",
            Self::DicomSeries => "dicom_series",
            Self::FilmFile => "film_file",
            Self::ViewerMessage => "viewer_message",
        }
    }

    /// Loads `data` as this target's input; errors are expected and ignored.
    pub fn run(self, data: &[u8]) {
        static LIMIT: Once = Once::new();
        LIMIT.call_once(|| volpt_scene::limits::set_memory_limit(FUZZ_MEMORY_LIMIT));
        DIR.with(|dir| self.run_in(dir.path(), data));
    }

    /// [`Self::run`] in `dir`, which holds no other files of this target's.
    fn run_in(self, dir: &Path, data: &[u8]) {
        let parts = split(data);
        let part = |i: usize| parts.get(i).copied().unwrap_or_default();
        match self {
            Self::MitsubaXml => {
                write(dir, "inc.xml", part(1));
                let params = String::from_utf8_lossy(part(2))
                    .lines()
                    .filter_map(|l| l.split_once('='))
                    .map(|(k, v)| (k.to_owned(), v.to_owned()))
                    .collect();
                assemble(&write(dir, "scene.xml", part(0)), params);
            }
            Self::Vol => assemble(&write(dir, "g.vol", data), Vec::new()),
            Self::Vdb => {
                let path = write(dir, "g.vdb", data);
                assemble(&path, Vec::new());
                read_sparse(&path);
            }
            Self::MetaImage => {
                let path = if parts.len() > 1 {
                    write(dir, "d.raw", part(1));
                    write(dir, "g.mhd", part(0))
                } else {
                    // A header naming `d.raw` must not find the last input's.
                    let _ = std::fs::remove_file(dir.join("d.raw"));
                    write(dir, "g.mha", data)
                };
                let _ = volpt_scene::read_metaimage(&path);
            }
            Self::Nrrd => {
                let path = if parts.len() > 1 {
                    write(dir, "d.raw", part(1));
                    write(dir, "g.nhdr", part(0))
                } else {
                    let _ = std::fs::remove_file(dir.join("d.raw"));
                    write(dir, "g.nrrd", data)
                };
                assemble(&path, Vec::new());
            }
            Self::TiffStack if parts.len() == 1 => assemble(&write(dir, "g.tif", data), Vec::new()),
            Self::TiffStack => assemble(&folder(dir, "stack", "tif", &parts), Vec::new()),
            Self::DicomSeries => assemble(&folder(dir, "series", "dcm", &parts), Vec::new()),
            Self::VtkLegacy => {
                let _ = volpt_scene::read_vtk(&write(dir, "g.vtk", data), None);
            }
            Self::VtkXml => {
                let _ = volpt_scene::read_vtk(&write(dir, "g.vti", data), None);
            }
            Self::TomlRaw => {
                write(dir, "g.raw", part(1));
                write(dir, "t.tf", part(2));
                assemble(&write(dir, "scene.toml", part(0)), Vec::new());
            }
            Self::TransferFunction => {
                let path = write(dir, "t.tf", data);
                if let Ok(tf) = TransferFunction::read(&path) {
                    let _ = tf.apply(&small_grid());
                }
            }
            Self::ExrEnvmap => {
                write(dir, "map.exr", data);
                assemble(
                    &write(dir, "scene.xml", ENVMAP_SCENE.as_bytes()),
                    Vec::new(),
                );
            }
            Self::FilmFile => {
                let path = write(dir, "part.vfilm", data);
                if let Ok(film) = volpt::FilmFile::read(&path, FUZZ_MEMORY_LIMIT) {
                    let _ = film.image();
                    let _ = volpt::merge_films(vec![("part".into(), film)], None);
                }
            }
            Self::ViewerMessage => VIEWER_SCENE.with(|scene| {
                apply_viewer_message(&mut scene.borrow_mut(), &String::from_utf8_lossy(data))
            }),
        }
    }
}

thread_local! {
    /// The scene viewer messages change: the example cube, loaded once per thread.
    static VIEWER_SCENE: std::cell::RefCell<volpt::Scene> = std::cell::RefCell::new(
        volpt::Scene::load(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/example/cube.xml"),
            &volpt::RenderSettings {
                resolution: Some((8, 8)),
                ..volpt::RenderSettings::default()
            },
        )
        .expect("the example scene loads"),
    );
}

/// What the viewer does with a text message: parse it, and apply a camera move or a parameter to
/// the scene (a refused value leaves the scene as it was, so inputs do not build on each other).
fn apply_viewer_message(scene: &mut volpt::Scene, text: &str) {
    use volpt::ParamValue;
    use volpt_view::protocol::{param_value, ClientMessage};
    match ClientMessage::parse(text) {
        Ok(ClientMessage::Camera {
            origin,
            target,
            fov,
            ..
        }) => {
            let _ = scene
                .set("camera.origin", ParamValue::Vec3(origin))
                .and_then(|()| scene.set("camera.target", ParamValue::Vec3(target)))
                .and_then(|()| match fov {
                    Some(fov) => scene.set("camera.fov", ParamValue::Float(fov)),
                    None => Ok(()),
                });
        }
        Ok(ClientMessage::Set { key, value }) => {
            if let Ok(value) = param_value(&key, &value) {
                let _ = scene.set(&key, value);
            }
        }
        _ => {}
    }
}

thread_local! {
    /// Each thread's directory for input files, made once and overwritten by every run (a fresh
    /// directory per input costs more than most parsers), in memory where Linux offers it.
    static DIR: tempfile::TempDir = {
        let shm = Path::new("/dev/shm");
        if shm.is_dir() {
            tempfile::tempdir_in(shm)
        } else {
            tempfile::tempdir()
        }
        .expect("a temporary directory")
    };
}

/// The scene an [`Target::ExrEnvmap`] input is the map of.
const ENVMAP_SCENE: &str = "<scene version=\"3.0.0\">\n<sensor type=\"perspective\">\
    <film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/>\
    <integer name=\"height\" value=\"4\"/></film></sensor>\n\
    <emitter type=\"envmap\"><string name=\"filename\" value=\"map.exr\"/></emitter>\n\
    <shape type=\"cube\"><bsdf type=\"null\"/><medium type=\"homogeneous\" name=\"interior\"/>\
    </shape>\n</scene>\n";

fn split(data: &[u8]) -> Vec<&[u8]> {
    let mut parts = Vec::new();
    let mut rest = data;
    while let Some(at) = rest.windows(SPLIT.len()).position(|w| w == SPLIT) {
        parts.push(&rest[..at]);
        rest = &rest[at + SPLIT.len()..];
    }
    parts.push(rest);
    parts
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("write a fuzz input file");
    path
}

/// A fresh folder `name` of `dir` holding each part as a file `0.EXT`, `1.EXT`, ...
fn folder(dir: &Path, name: &str, extension: &str, parts: &[&[u8]]) -> PathBuf {
    let folder = dir.join(name);
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir(&folder).expect("a fuzz input folder");
    for (i, part) in parts.iter().enumerate() {
        write(&folder, &format!("{i}.{extension}"), part);
    }
    folder
}

fn assemble(path: &Path, params: Vec<(String, String)>) {
    let config = Config {
        params,
        ..Config::default()
    };
    if let Ok(builder) = builder_for(path) {
        let _ = SceneAssembler::new(config).assemble(builder.as_ref());
    }
}

/// A VDB's float grid kept sparse and read as the renderers read it: the brick table the loader
/// wrote must pass the lookup's checks, the majorant grid is built from it, and no lookup may
/// exceed its cell's majorant (delta tracking's one requirement of the majorants).
fn read_sparse(path: &Path) {
    use volpt_core::grid::{Grid, GridMapping};
    use volpt_core::majorant::{build_majorants, MajorantGrid};
    use volpt_core::{Aabb, Vec3};
    use volpt_scene::vdb::{read_vdb, Sparsity, VdbOptions};
    let options = VdbOptions {
        sparsity: Sparsity::Always,
        ..VdbOptions::default()
    };
    let Ok(grid) = read_vdb(path, &options) else {
        return;
    };
    if let Err(e) = volpt_scene::sparse::check(&grid) {
        panic!("the VDB loader wrote a sparse grid the lookup refuses: {e}");
    }
    let bounds = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let mapping = GridMapping::cell_centred(bounds, grid.resolution);
    let density = Grid::<1>::sparse(&grid.data, grid.resolution, mapping);
    const CELLS: u32 = 4;
    let mut cells = vec![0.0; (CELLS * CELLS * CELLS) as usize];
    build_majorants(&density, 1.0, bounds, [CELLS; 3], &mut cells);
    let majorants = MajorantGrid::new(&cells, [CELLS; 3], bounds);
    const STEPS: u32 = 7;
    for i in 0..STEPS * STEPS * STEPS {
        let u = |k: u32| ((k % STEPS) as f32 + 0.5) / STEPS as f32;
        let p = Vec3::new(u(i), u(i / STEPS), u(i / (STEPS * STEPS)));
        let (value, bound) = (density.lookup(p)[0], majorants.at_point(p));
        // NaN samples compare with nothing; a number must not exceed its bound.
        assert!(
            value.partial_cmp(&bound) != Some(std::cmp::Ordering::Greater),
            "a lookup of {value} above its majorant {bound} at {p:?}"
        );
    }
}

fn small_grid() -> GridDesc {
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution: [2, 2, 2],
        channels: 1,
        bounds: Bounds {
            min: [0.0; 3],
            max: [1.0; 3],
        },
        convention: GridConvention::Cell,
        data: vec![0.0, 1.0, 2.0, 5.0, 10.0, 20.0, 40.0, 255.0],
    }
}

/// Seed inputs for `target`: the repository's fixtures and scenes where they fit, and small
/// files written by volpt's own writers (every element type and compression where it matters).
pub fn seeds(target: Target) -> Vec<Vec<u8>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let fixture = |p: &str| std::fs::read(root.join(p)).unwrap_or_default();
    let join = |parts: &[&[u8]]| parts.join(SPLIT);
    let dir = tempfile::tempdir().expect("a temporary directory");
    let written = |name: &str, f: &dyn Fn(&Path)| {
        let path = dir.path().join(name);
        f(&path);
        std::fs::read(&path).expect("a written seed")
    };
    let grid = small_grid();
    match target {
        Target::MitsubaXml => vec![
            join(&[
                &fixture("volpt-scene/tests/fixtures/mitsuba06/scene.xml"),
                b"",
                b"",
            ]),
            join(&[&fixture("volpt-scene/tests/fixtures/mitsuba3/scene.xml")]),
            join(&[
                &fixture("volpt-scene/tests/fixtures/params/scene.xml"),
                b"",
                b"scale=2\nalbedo=0.5",
            ]),
            join(&[
                b"<scene version=\"0.6.0\">\n<default name=\"s\" value=\"2\"/>\n\
                  <include filename=\"inc.xml\"/>\n<shape type=\"cube\"><bsdf type=\"null\"/>\
                  <ref name=\"interior\" id=\"fog\"/></shape>\n</scene>\n",
                &fixture("volpt-scene/tests/fixtures/include/parts/media.xml"),
                b"s=3",
            ]),
            join(&[&fixture("scenes/homogeneous-cube/scene.xml")]),
            join(&[&fixture("scenes/example/cube.xml")]),
        ],
        // Files written by the real OpenVDB library (scenes/vdb/make_fixtures.py): float and half
        // leaves, blosc, zip and uncompressed, transforms, a vec3 grid, a sparse box.
        Target::Vdb => [
            "bucky.vdb",
            "bucky-half.vdb",
            "bucky-zip.vdb",
            "bucky-half-none.vdb",
            "halves.vdb",
            "transform.vdb",
            "cloud-rgb.vdb",
            "sparse-cloud.vdb",
        ]
        .iter()
        .map(|f| fixture(&format!("scenes/vdb/fixtures/{f}")))
        .collect(),
        Target::Vol => vec![{
            written("g.vol", &|p| {
                volpt_scene::write_vol(
                    p,
                    &volpt_scene::VolGrid {
                        resolution: grid.resolution,
                        channels: 1,
                        bbox: grid.bounds,
                        data: grid.data.clone(),
                    },
                )
                .expect("write a .vol seed")
            })
        }],
        Target::MetaImage => {
            let mut seeds = vec![
                fixture("volpt-scene/tests/fixtures/metaimage/msb.mha"),
                join(&[
                    &fixture("volpt-scene/tests/fixtures/metaimage/tiny.mhd")
                        .replace_ascii("tiny.raw", "d.raw"),
                    &fixture("volpt-scene/tests/fixtures/metaimage/tiny.raw"),
                ]),
            ];
            for (scalar, compressed) in [
                (volpt_scene::ScalarType::U8, false),
                (volpt_scene::ScalarType::F32, true),
                (volpt_scene::ScalarType::I16, true),
            ] {
                let options = MetaImageOptions {
                    scalar,
                    byte_order: volpt_scene::ByteOrder::Little,
                    compressed,
                };
                seeds.push(written("g.mha", &|p| {
                    volpt_scene::write_metaimage(p, &grid, &options).expect("write a .mha seed")
                }));
            }
            seeds
        }
        Target::VtkLegacy => vec![
            fixture("volpt-scene/tests/fixtures/vtk/tiny_ascii.vtk"),
            written("g.vtk", &|p| {
                volpt_scene::write_vtk(p, &grid, "density").expect("write a .vtk seed")
            }),
        ],
        Target::VtkXml => vec![
            fixture("volpt-scene/tests/fixtures/vtk/tiny_ascii.vti"),
            written("g.vti", &|p| {
                volpt_scene::write_vtk(p, &grid, "density").expect("write a .vti seed")
            }),
        ],
        Target::TomlRaw => vec![
            join(&[
                &fixture("volpt-cli/tests/fixtures/toml/raw-transfer.toml")
                    .replace_ascii("$dir/tiny.raw", "g.raw")
                    .replace_ascii("tiny.tf", "t.tf"),
                &fixture("volpt-cli/tests/fixtures/toml/tiny.raw"),
                &fixture("volpt-cli/tests/fixtures/toml/tiny.tf"),
            ]),
            join(&[
                &fixture("volpt-cli/tests/fixtures/toml/minimal.toml")
                    .replace_ascii("tiny.raw", "g.raw"),
                &fixture("volpt-cli/tests/fixtures/toml/tiny.raw"),
            ]),
        ],
        Target::FilmFile => {
            let film = |w: u32, h: u32| {
                let mut film = volpt::Film::new(w, h);
                for (i, sum) in film.flat_sums_mut().iter_mut().enumerate() {
                    *sum = i as f64 * 0.5;
                }
                film
            };
            vec![
                written("part.vfilm", &|p| {
                    volpt::FilmFile {
                        fingerprint: 7,
                        seed: 3,
                        ranges: vec![0..4, 9..12],
                        film: film(3, 2),
                    }
                    .write(p)
                    .expect("write a film seed")
                }),
                written("render.ckpt", &|p| {
                    volpt_film::Checkpoint::write_film(p, 7, 3, 5, &film(2, 2))
                        .expect("write a checkpoint seed")
                }),
            ]
        }
        Target::ViewerMessage => [
            r#"{"type":"camera","origin":[3.2,2.4,4],"target":[0,-0.1,0],"fov":30,"interactive":true}"#,
            r#"{"type":"camera","origin":[0,5,0],"target":[0,0,0]}"#,
            r#"{"type":"set","key":"medium.albedo","value":[0.5,0.25,1]}"#,
            r#"{"type":"set","key":"max_depth","value":-1}"#,
            r#"{"type":"set","key":"phase.g","value":0.5}"#,
            r#"{"type":"set","key":"spp","value":4294967295}"#,
            r#"{"type":"exposure","value":-2}"#,
            r#"{"type":"format","format":"png"}"#,
            r#"{"type":"ack","frame":18446744073709551615}"#,
            r#"{"type":"reset"}"#,
        ]
        .iter()
        .map(|m| m.as_bytes().to_vec())
        .collect(),
        Target::TransferFunction => vec![
            fixture("volpt-scene/tests/fixtures/transfer/bucky.txt"),
            fixture("volpt-cli/tests/fixtures/toml/tiny.tf"),
            fixture("scenes/bucky/bucky.tf"),
        ],
        // Files written by pynrrd, tifffile and pydicom (scenes/scanners/make_fixtures.py).
        Target::Nrrd => {
            let scanned = |f: &str| fixture(&format!("scenes/scanners/fixtures/{f}"));
            let mut seeds: Vec<Vec<u8>> = [
                "raw.nrrd",
                "gzip.nrrd",
                "mirrored-x.nrrd",
                "permuted-xy.nrrd",
            ]
            .iter()
            .map(|f| scanned(f))
            .collect();
            let header = scanned("detached.nhdr").replace_ascii("detached.raw.gz", "d.raw");
            seeds.push(join(&[&header, &scanned("detached.raw.gz")]));
            seeds
        }
        Target::TiffStack => {
            let scanned = |f: &str| fixture(&format!("scenes/scanners/fixtures/{f}"));
            let slices: Vec<Vec<u8>> = (8..12)
                .map(|k| scanned(&format!("tiff-folder/slice_{k}.tif")))
                .collect();
            let slices: Vec<&[u8]> = slices.iter().map(Vec::as_slice).collect();
            vec![
                scanned("stack-u16.tif"),
                scanned("stack-u8-deflate.tif"),
                scanned("stack-f32.tif"),
                join(&slices),
            ]
        }
        Target::DicomSeries => {
            let series = |dir: &str, names: &[&str]| {
                let files: Vec<Vec<u8>> = names
                    .iter()
                    .map(|n| fixture(&format!("scenes/scanners/fixtures/{dir}/{n}")))
                    .collect();
                let files: Vec<&[u8]> = files.iter().map(Vec::as_slice).collect();
                join(&files)
            };
            vec![
                series("dicom-axial", &["IM0001", "IM0002", "IM0003", "IM0004"]),
                series(
                    "dicom-mirrored",
                    &["slice0.dcm", "slice1.dcm", "slice2.dcm", "slice3.dcm"],
                ),
                series("dicom-coronal", &["c0.dcm", "c1.dcm", "c2.dcm"]),
                series("dicom-jpeg", &["jpeg.dcm"]),
            ]
        }
        Target::ExrEnvmap => vec![
            written("rgb.exr", &|p| {
                exr::prelude::write_rgb_file(p, 8, 4, |x, y| (x as f32, y as f32, 0.5f32))
                    .expect("write an EXR seed")
            }),
            written("rgba.exr", &|p| {
                exr::prelude::write_rgba_file(p, 4, 2, |x, _| (1.0f32, x as f32, 0.5f32, 1.0f32))
                    .expect("write an EXR seed")
            }),
        ],
    }
    .into_iter()
    .filter(|s| !s.is_empty())
    .collect()
}

/// Text replacement in a byte seed (fixtures name their files; the targets use fixed names).
trait ReplaceAscii {
    fn replace_ascii(&self, from: &str, to: &str) -> Vec<u8>;
}

impl ReplaceAscii for Vec<u8> {
    fn replace_ascii(&self, from: &str, to: &str) -> Vec<u8> {
        String::from_utf8_lossy(self).replace(from, to).into_bytes()
    }
}

/// A small deterministic mutator for the short run in `cargo test` (libFuzzer has its own):
/// bit flips, boundary bytes, numbers swapped for extreme ones, insertions, deletions, splices.
pub struct Mutator {
    state: u64,
}

impl Mutator {
    pub fn new(seed: u64) -> Self {
        Self {
            state: seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1,
        }
    }

    fn next(&mut self) -> u64 {
        // xorshift64*
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        self.state.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    /// `input` changed in one to four places.
    pub fn mutate(&mut self, input: &[u8]) -> Vec<u8> {
        const NUMBERS: [&str; 10] = [
            "0",
            "-1",
            "4294967295",
            "2147483648",
            "18446744073709551615",
            "1e38",
            "3e38",
            "nan",
            "inf",
            "65536",
        ];
        const BYTES: [u8; 6] = [0, 0xff, 0x7f, 0x80, b'\n', b'$'];
        let mut out = input.to_vec();
        for _ in 0..1 + self.below(4) {
            let at = self.below(out.len() + 1);
            match self.below(6) {
                0 if !out.is_empty() => {
                    let i = at.min(out.len() - 1);
                    out[i] ^= 1 << self.below(8);
                }
                1 if !out.is_empty() => {
                    let i = at.min(out.len() - 1);
                    out[i] = BYTES[self.below(BYTES.len())];
                }
                2 => {
                    // Replace the number at or after `at` with an extreme one.
                    let start = (at..out.len()).find(|&i| out[i].is_ascii_digit());
                    if let Some(start) = start {
                        let end = (start..out.len())
                            .find(|&i| !out[i].is_ascii_digit())
                            .unwrap_or(out.len());
                        let number = NUMBERS[self.below(NUMBERS.len())].as_bytes();
                        out.splice(start..end, number.iter().copied());
                    }
                }
                3 => {
                    let len = self.below(16);
                    out.splice(at..at, (0..len).map(|_| self.next() as u8));
                }
                4 if !out.is_empty() => {
                    let end = (at + 1 + self.below(32)).min(out.len());
                    out.drain(at.min(end)..end);
                }
                _ if !out.is_empty() => {
                    // Repeat a slice of the input somewhere else (duplicated elements, lines).
                    let from = self.below(out.len());
                    let len = 1 + self.below(64.min(out.len() - from));
                    let piece = out[from..from + len].to_vec();
                    let to = self.below(out.len() + 1);
                    out.splice(to..to, piece);
                }
                _ => {}
            }
        }
        out
    }
}
