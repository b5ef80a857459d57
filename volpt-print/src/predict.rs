//! The real predictor: a print's appearance from straight above, rendered by volpt (any backend
//! the facade opens: the CPU, a GPU, several GPUs).
//!
//! **Scene.** The print is the medium's box, voxel `(x, y, z)` the grid cell at
//! `[x, x + 1] * sx` by `[y, y + 1] * sy` by `[z, z + 1] * sz` (nearest lookup: a voxel is one
//! material), its top surface at `z = depth * sz`. The boundary is the resin's surface
//! ([`RenderPredictor::boundary`]: a smooth dielectric of IOR 1.5 by default, or index-matched);
//! the illumination a constant environment of radiance 1 from every direction (what the print
//! reflects and transmits of uniform white light; a print standing on a black table would have a
//! black lower hemisphere: not offered yet). Paths are unlimited in length with Russian roulette
//! from depth 5 (Mitsuba's defaults).
//!
//! **Camera.** One pixel per surface texel, looking straight down: Mitsuba's `orthographic`
//! sensor over the print's top face, its film spanning the face exactly, whatever the texels'
//! aspect.
//!
//! **Materials.** The print is rendered as what it is: a material-indexed volume (volpt-scene's
//! [`IndexedDesc`]: one byte per voxel naming a row of the material table, each material with its
//! RGB `sigma_s`, `sigma_a` and its own `g`), one chromatic render giving the three channels. The
//! scene is built once per print geometry and table; later predictions replace its indices
//! ([`volpt::Scene::set_indices`]), so a backend re-uploads exactly what changed (one byte a
//! voxel).
//!
//! **Noise.** Each prediction is an unbiased render of `spp` samples per texel and channel, made
//! as two independent halves (seeds `seed` and `seed + 1`, the same each time: one print always
//! predicts the same image). The halves' difference estimates each texel's standard error,
//! `|a - b| / 2` per channel (the mean of two equal-variance estimates has variance
//! `E[(a - b)^2] / 4`), kept as [`RenderPredictor::standard_error`]: the update moves an aim by
//! `step` times the prediction's error, so a standard error well below the error the loop is
//! removing is what "enough samples" means: the loop asks for four times the samples
//! ([`Predictor::more_samples`], up to [`RenderPredictor::max_spp`]) while a prediction's noise is
//! above its bound ([`crate::compensate`]'s module docs).
//!
//! **Where.** On a backend of this process ([`RenderPredictor::new`]: the CPU, a GPU, several GPUs
//! through `--gpus`, whose renders split each prediction's samples between them), or elsewhere
//! ([`RenderPredictor::elsewhere`]: each prediction written as a volpt TOML scene and its slice
//! stack, rendered by a function given the scene's path, such as Python's Ray cluster, which
//! splits the samples into ranges rendered on its nodes and merges their films).
//!
//! **Progress and interruption**: each render reports to the predictor's observer
//! ([`RenderPredictor::with_observer`]), which may stop it (Ctrl-C); a prediction so stopped is
//! not whole, and [`Predictor::interrupted`] says so.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use thiserror::Error;
use volpt::scene_files::material::{IndexedDesc, MaterialDesc};
use volpt::scene_files::{
    AlbedoDesc, BoundaryDesc, Bounds, BsdfDesc, CameraDesc, DensityDesc, EnvironmentDesc, FilmDesc,
    FovAxis, GridLookup, GridStorage, IntegratorDesc, MediumDesc, Projection, SceneBuilder,
    SceneDescription, SceneError,
};
use volpt::{Backend, Observer, Quiet, RenderRequest, RenderSettings, Scene};

use crate::colour::LinearRgb;
use crate::compensate::Predictor;
use crate::print::VoxelPrint;

#[derive(Debug, Error)]
pub enum PredictError {
    #[error(transparent)]
    Volpt(#[from] volpt::Error),
    /// Writing a prediction's scene for [`RenderPredictor::elsewhere`].
    #[error(transparent)]
    Write(#[from] crate::PrintError),
}

/// Renders a print's scene elsewhere ([`RenderPredictor::elsewhere`]): given the path of a volpt
/// TOML scene, a sample count `n` and a seed, the image of samples `0..n` of every pixel (each
/// pixel's mean), or `None` where it stopped (Ctrl-C, an error its caller keeps).
pub type RenderFiles<'b> = Box<dyn FnMut(&Path, u32, u32) -> Option<volpt::Image> + Send + 'b>;

/// Where a predictor's renders run.
enum Renders<'b> {
    /// A backend of this process, on the scene built in memory.
    Backend(&'b Backend),
    /// A function given the scene as files, written into `dir` for each prediction.
    Files {
        dir: PathBuf,
        render: RenderFiles<'b>,
    },
}

/// The scene file [`RenderPredictor::elsewhere`] writes (its slice stack beside it, `slices/`).
pub const ELSEWHERE_SCENE: &str = "scene.toml";

/// Renders prints from above with volpt (see the module docs).
pub struct RenderPredictor<'b> {
    renders: Renders<'b>,
    /// Samples per texel of the next prediction (one chromatic render: every channel).
    pub spp: u32,
    /// The most samples per texel [`Predictor::more_samples`] raises `spp` to.
    pub max_spp: u32,
    pub seed: u32,
    /// The resin's surface.
    pub boundary: BsdfDesc,
    /// The scene of the last print's geometry, whose grids the next prediction replaces.
    scene: Option<(Geometry, Scene)>,
    standard_error: Vec<LinearRgb>,
    observer: Arc<dyn Observer + Send + Sync>,
    interrupted: bool,
}

/// What fixes a prediction's scene apart from its voxels' indices.
#[derive(Clone, Debug, PartialEq)]
struct Geometry {
    resolution: [u32; 3],
    voxel_size: [f64; 3],
    materials: Vec<MaterialDesc>,
    boundary: BsdfDesc,
}

impl<'b> RenderPredictor<'b> {
    /// The most samples per texel a predictor takes unless told otherwise.
    pub const MAX_SPP: u32 = 4096;

    /// A predictor rendering on `backend` with `spp` samples per texel (at most
    /// [`RenderPredictor::MAX_SPP`] when the loop asks for more), a smooth dielectric surface of
    /// IOR 1.5 (the order of the photopolymer resins') in air.
    pub fn new(backend: &'b Backend, spp: u32) -> Self {
        Self::with_renders(Renders::Backend(backend), spp)
    }

    /// A predictor as [`RenderPredictor::new`]'s whose renders run elsewhere: each prediction's
    /// scene is written into `dir` (created; [`ELSEWHERE_SCENE`] and its slice stack `slices/`,
    /// replaced by the next prediction's) and `render` renders it (see [`RenderFiles`]). `dir`
    /// must be where the renderer reads it (a shared file system for a cluster).
    pub fn elsewhere(dir: PathBuf, render: RenderFiles<'b>, spp: u32) -> Self {
        Self::with_renders(Renders::Files { dir, render }, spp)
    }

    fn with_renders(renders: Renders<'b>, spp: u32) -> Self {
        RenderPredictor {
            renders,
            spp,
            max_spp: spp.max(Self::MAX_SPP),
            seed: 0,
            boundary: BsdfDesc::Dielectric {
                int_ior: 1.5,
                ext_ior: 1.0,
            },
            scene: None,
            standard_error: Vec::new(),
            observer: Arc::new(Quiet),
            interrupted: false,
        }
    }

    /// The same predictor, its renders reporting their progress to `observer`, which may stop
    /// them (a stopped prediction is [`Predictor::interrupted`]).
    pub fn with_observer(mut self, observer: Arc<dyn Observer + Send + Sync>) -> Self {
        self.observer = observer;
        self
    }

    /// The scene a prediction of `print` renders (the module docs): to inspect it, export it
    /// (volpt-scene's Mitsuba 3 writer) or render it otherwise.
    pub fn description(&self, print: &VoxelPrint) -> Result<SceneDescription, SceneError> {
        PrintScene {
            print,
            geometry: self.geometry(print),
            spp: self.spp,
        }
        .build(&[])
    }

    /// The scene a prediction of `print` renders (as [`RenderPredictor::description`]) as a volpt
    /// TOML scene whose volume is the slice stack in the folder `slices` (relative to the TOML
    /// file): `volpt render` renders it, `volpt scene export` writes it for Mitsuba 3. Its image is
    /// the top view as a camera sees it: the prediction's rows reversed (a prediction's row 0 is
    /// texel row 0, a slice's top row; the camera's top row is the print's far edge, y at its
    /// largest).
    pub fn toml_scene(&self, print: &VoxelPrint, slices: &str) -> String {
        let [w, h, d] = print.resolution();
        let [sx, sy, sz] = print.voxel_size();
        let size = [f64::from(w) * sx, f64::from(h) * sy, f64::from(d) * sz];
        let mut t = String::new();
        let mut line = |text: String| {
            t.push_str(&text);
            t.push('\n');
        };
        line("# A voxel print as volpt-print predicts it: its top view under white light, one pixel a".into());
        line(
            "# texel (docs/printing.md). `volpt render` renders it; `volpt scene export` writes it"
                .into(),
        );
        line("# for Mitsuba 3.".into());
        line("[volume]".into());
        line(format!("file = {slices:?}"));
        line("format = \"png\"".into());
        line(format!(
            "bounds = [[0.0, 0.0, 0.0], [{:?}, {:?}, {:?}]]",
            size[0], size[1], size[2]
        ));
        for m in print.materials() {
            line(String::new());
            line("[[materials]]".into());
            line(format!("name = {:?}", m.name));
            if let Some(colour) = m.colour {
                line(format!("colour = {colour:?}"));
            }
            line(format!("sigma_s = {:?}", m.sigma_s));
            line(format!("sigma_a = {:?}", m.sigma_a));
            line(format!("g = {:?}", m.g));
        }
        line(String::new());
        line("[boundary]".into());
        match self.boundary {
            BsdfDesc::Null => line("bsdf = \"null\"".into()),
            BsdfDesc::Dielectric { int_ior, ext_ior } => line(format!(
                "bsdf = \"dielectric\"\nint_ior = {int_ior:?}\next_ior = {ext_ior:?}"
            )),
            BsdfDesc::RoughDielectric {
                alpha,
                int_ior,
                ext_ior,
            } => line(format!(
                "bsdf = \"roughdielectric\"\nalpha = {alpha:?}\nint_ior = {int_ior:?}\n\
                 ext_ior = {ext_ior:?}"
            )),
        }
        line(String::new());
        line("[camera]".into());
        line("projection = \"orthographic\"".into());
        let centre = [0.5 * size[0], 0.5 * size[1]];
        line(format!(
            "origin = [{:?}, {:?}, {:?}]",
            centre[0],
            centre[1],
            size[2] + sz
        ));
        line(format!("target = [{:?}, {:?}, 0.0]", centre[0], centre[1]));
        line("up = [0.0, 1.0, 0.0]".into());
        line(format!("extent = [{:?}, {:?}]", size[0], size[1]));
        line(String::new());
        line(format!("[film]\nwidth = {w}\nheight = {h}\n"));
        line(format!("[sampler]\nspp = {}\n", self.spp.max(1)));
        line("[integrator]\nmax_depth = -1\nrr_depth = 5\n".into());
        line("[environment]\nradiance = 1.0".into());
        t
    }

    /// The scene [`RenderPredictor::elsewhere`] writes: [`RenderPredictor::toml_scene`] over the
    /// stack `slices/` beside it.
    fn toml_scene_of(&self, print: &VoxelPrint) -> String {
        self.toml_scene(print, "slices")
    }

    fn geometry(&self, print: &VoxelPrint) -> Geometry {
        Geometry {
            resolution: print.resolution(),
            voxel_size: print.voxel_size(),
            materials: print.materials().to_vec(),
            boundary: self.boundary,
        }
    }
}

/// The scene of a print, built in code.
struct PrintScene<'a> {
    print: &'a VoxelPrint,
    geometry: Geometry,
    spp: u32,
}

impl SceneBuilder for PrintScene<'_> {
    fn source(&self) -> String {
        "volpt-print's top view of a voxel print".into()
    }

    fn build(&self, _params: &[(String, String)]) -> Result<SceneDescription, SceneError> {
        let [w, h, d] = self.geometry.resolution;
        let [sx, sy, sz] = self.geometry.voxel_size;
        let size = [f64::from(w) * sx, f64::from(h) * sy, f64::from(d) * sz];
        let bounds = Bounds {
            min: [0.0; 3],
            max: size.map(|s| s as f32),
        };
        let volume = IndexedDesc::new(
            Path::new("the print"),
            self.geometry.materials.clone(),
            self.geometry.resolution,
            bounds,
            self.print.indices(),
        )?;
        // Mitsuba's camera frame, columns left, up, view direction and origin: looking down -z
        // with +y up puts +x to the image's right and +y at its top. The orthographic film spans
        // camera-space x in [-1, 1] and y in [-h/w, h/w]: scaling x by half the print's width and
        // y by w/h times half its height maps the film onto the top face, one pixel per texel.
        let aspect = f64::from(w) / f64::from(h);
        let half = [0.5 * size[0], 0.5 * size[1] * aspect];
        let above = size[2] + sz;
        let to_world = [
            [-half[0] as f32, 0.0, 0.0, (0.5 * size[0]) as f32],
            [0.0, half[1] as f32, 0.0, (0.5 * size[1]) as f32],
            [0.0, 0.0, -1.0, above as f32],
            [0.0, 0.0, 0.0, 1.0],
        ];
        Ok(SceneDescription {
            lights: Default::default(),
            camera: CameraDesc {
                to_world,
                // Unused by an orthographic camera.
                fov_degrees: 0.0,
                fov_axis: FovAxis::X,
                projection: Projection::Orthographic,
            },
            film: FilmDesc {
                width: w,
                height: h,
            },
            spp: self.spp,
            integrator: IntegratorDesc {
                max_depth: None,
                rr_depth: Some(5),
            },
            boundary: BoundaryDesc {
                bounds,
                bsdf: self.geometry.boundary,
                mesh: None,
            },
            medium: MediumDesc {
                phase: volume.phase(),
                density: DensityDesc::Indexed(volume),
                scale: 1.0,
                // Not read: each voxel's material gives its albedo.
                albedo: AlbedoDesc::Constant([0.0; 3]),
                // Not read either: a voxel is one material (no interpolation between indices).
                lookup: GridLookup::Nearest,
                storage: GridStorage::Dense,
            },
            environment: EnvironmentDesc::Constant([1.0; 3]),
        })
    }
}

impl Predictor for RenderPredictor<'_> {
    type Error = PredictError;

    fn predict(&mut self, print: &VoxelPrint) -> Result<Vec<LinearRgb>, PredictError> {
        let geometry = self.geometry(print);
        let [w, h, _] = geometry.resolution;
        // Two independent halves (spp / 2 and the rest), averaged by their sample counts.
        let halves = [self.spp / 2, self.spp - self.spp / 2];
        // Stopped already (Ctrl-C while the loop halftoned): no render to start.
        self.interrupted = self.observer.cancelled();
        if self.interrupted {
            self.standard_error.clear();
            return Ok(Vec::new());
        }
        let toml = matches!(self.renders, Renders::Files { .. }).then(|| self.toml_scene_of(print));
        let rendered = match &mut self.renders {
            Renders::Backend(backend) => {
                match &mut self.scene {
                    Some((built, scene)) if *built == geometry => {
                        scene.set_indices(print.indices())?
                    }
                    _ => {
                        let builder = PrintScene {
                            print,
                            geometry: geometry.clone(),
                            spp: self.spp.max(1),
                        };
                        let scene = Scene::build(&builder, &RenderSettings::default())?;
                        self.scene = Some((geometry.clone(), scene));
                    }
                }
                let (_, scene) = self.scene.as_ref().expect("built above");
                let observer = &*self.observer;
                render_halves(halves, self.seed, |n, seed| {
                    let mut film = scene.film();
                    let request = RenderRequest::samples(0..n).with_seed(seed);
                    let done = backend.render(scene, &mut film, request, observer)?;
                    Ok((!done.cancelled(&(0..n))).then(|| film.image(n)))
                })?
            }
            Renders::Files { dir, render } => {
                let scene = write_scene(dir, print, toml.as_deref().unwrap_or_default())?;
                render_halves(halves, self.seed, |n, seed| Ok(render(&scene, n, seed)))?
            }
        };
        let Some(images) = rendered else {
            self.interrupted = true;
            self.standard_error.clear();
            return Ok(Vec::new());
        };
        let total: f64 = images.iter().map(|(n, _)| n).sum();
        let mut texels = Vec::with_capacity(w as usize * h as usize);
        let mut errors = Vec::with_capacity(texels.capacity());
        // Image row 0 is the print's top edge, texel row h - 1.
        for y in 0..h {
            for x in 0..w {
                let at = |image: &volpt::Image| image.pixel(x, h - 1 - y).map(f64::from);
                texels.push(LinearRgb([0, 1, 2].map(|c| {
                    images.iter().map(|(n, im)| n * at(im)[c]).sum::<f64>() / total
                })));
                errors.push(LinearRgb(match images.as_slice() {
                    [(_, a), (_, b)] => [0, 1, 2].map(|c| 0.5 * (at(a)[c] - at(b)[c]).abs()),
                    _ => [f64::INFINITY; 3],
                }));
            }
        }
        self.standard_error = errors;
        Ok(texels)
    }

    /// Estimated from the prediction's two independent halves (see the module docs).
    fn standard_error(&self) -> Option<&[LinearRgb]> {
        Some(&self.standard_error)
    }

    fn more_samples(&mut self) -> bool {
        let more = self.spp.saturating_mul(4).min(self.max_spp);
        let grew = more > self.spp;
        self.spp = more;
        grew
    }

    fn samples(&self) -> Option<u32> {
        Some(self.spp)
    }

    fn interrupted(&self) -> bool {
        self.interrupted
    }
}

/// The two halves' images (`(samples, image)`, halves of no samples left out), each rendered by
/// `render(n, seed)` with its own seed (`seed`, `seed + 1`); `None` if one stopped.
fn render_halves(
    halves: [u32; 2],
    seed: u32,
    mut render: impl FnMut(u32, u32) -> Result<Option<volpt::Image>, PredictError>,
) -> Result<Option<Vec<(f64, volpt::Image)>>, PredictError> {
    let mut images = Vec::new();
    for (k, &n) in halves.iter().enumerate() {
        if n == 0 {
            continue;
        }
        match render(n, seed.wrapping_add(k as u32))? {
            Some(image) => images.push((f64::from(n), image)),
            None => return Ok(None),
        }
    }
    Ok(Some(images))
}

/// Writes `print`'s scene `toml` into `dir` ([`ELSEWHERE_SCENE`] and `slices/`), replacing the
/// last prediction's; returns the scene's path.
fn write_scene(dir: &Path, print: &VoxelPrint, toml: &str) -> Result<PathBuf, PredictError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| crate::PrintError::Io { path, source }
    };
    let slices = dir.join("slices");
    match std::fs::remove_dir_all(&slices) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(io(&slices)(e).into()),
        _ => {}
    }
    crate::slices::write_slices(print, &slices)?;
    let scene = dir.join(ELSEWHERE_SCENE);
    std::fs::write(&scene, toml).map_err(io(&scene))?;
    Ok(scene)
}
