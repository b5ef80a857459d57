//! A compensation as the front ends run it (`volpt print compensate`, Python's
//! `volpt.compensate_print`): a target PNG, a material table file, the print's depth and the
//! loop's options in; the record ([`crate::record`]) out, with the kept and the naive print as
//! volpt scenes ([`PRINT_SCENE`], [`NAIVE_SCENE`]: `volpt render` renders them, `volpt scene
//! export` writes them for Mitsuba 3). Both front ends call [`run`], so they
//! make the same record from the same arguments.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use thiserror::Error;
use volpt::{Backend, Observer};

use crate::compensate::{
    compensate, print_for, CompensateError, Compensation, Iteration, Options, Setup,
};
use crate::error::PrintError;
use crate::halftone::Halftone;
use crate::material::{Inks, MaterialFile};
use crate::predict::{PredictError, RenderFiles, RenderPredictor};
use crate::record::write_record;
use crate::slices::write_slices;
use crate::target::Target;

/// The voxel size when neither the job nor the material file gives one, in millimetres: 600 dpi
/// across (0.0423 mm) and the thesis's 27 um layers.
pub const VOXEL_SIZE: [f64; 3] = [0.0423, 0.0423, 0.027];

/// The record's volpt scenes of the kept print and of the naive one (the first iteration's), and
/// the naive print's slice stack (the kept one's is `slices/`).
pub const PRINT_SCENE: &str = "print.toml";
pub const NAIVE_SCENE: &str = "naive.toml";
pub const NAIVE_SLICES: &str = "naive_slices";
/// Where [`Renderer::Elsewhere`]'s predictions are written while the job runs (removed after).
pub const RENDERS: &str = "renders";

/// Where a job's predictions render.
pub enum Renderer<'b> {
    /// A backend of this process: the CPU, a GPU, or several (`--gpus`).
    Backend(&'b Backend),
    /// A function given each prediction's scene as files under the record's [`RENDERS`] folder
    /// ([`RenderPredictor::elsewhere`]): Python's Ray cluster.
    Elsewhere(RenderFiles<'b>),
}

/// What a compensation is asked to do.
#[derive(Clone, Debug)]
pub struct Job {
    /// The target image (PNG, sRGB).
    pub target: PathBuf,
    /// The material table (see [`MaterialFile`]); its materials named cyan, magenta, yellow,
    /// black and white are the inks.
    pub materials: PathBuf,
    /// The folder the record goes to; must not already hold one's slices.
    pub out: PathBuf,
    /// The print's depth in voxel layers.
    pub layers: u32,
    /// The layers under each texel that hold its colour (white below them).
    pub colour_layers: u32,
    /// The voxel size (x, y, layer height); `None`: the material file's, else [`VOXEL_SIZE`].
    pub voxel_size: Option<[f64; 3]>,
    /// Samples per texel of the first prediction, and the most the noise control may raise it to.
    pub spp: u32,
    pub max_spp: u32,
    /// The seed of the renders' random streams and of the halftone's threshold offsets.
    pub seed: u32,
    /// The resin surface's index of refraction; `None`: index-matched (no surface).
    pub ior: Option<f32>,
    pub options: Options,
}

impl Job {
    /// A job with the defaults the front ends show: 100 layers, 40 of them colour, 16 samples
    /// per texel up to [`RenderPredictor::MAX_SPP`], seed 0, IOR 1.5, [`Options::default`].
    pub fn new(target: PathBuf, materials: PathBuf, out: PathBuf) -> Job {
        Job {
            target,
            materials,
            out,
            layers: 100,
            colour_layers: 40,
            voxel_size: None,
            spp: 16,
            max_spp: RenderPredictor::MAX_SPP,
            seed: 0,
            ior: Some(1.5),
            options: Options::default(),
        }
    }
}

/// Why a compensation could not run or finish (boxed: these errors are large beside a result).
#[derive(Debug, Error)]
pub enum JobError {
    #[error(transparent)]
    Print(Box<PrintError>),
    #[error(transparent)]
    Compensate(Box<CompensateError<PredictError>>),
    #[error("{}: {field}: expected {expected}, found {found}", path.display())]
    Invalid {
        path: PathBuf,
        field: &'static str,
        expected: String,
        found: String,
    },
}

impl From<PrintError> for JobError {
    fn from(e: PrintError) -> Self {
        JobError::Print(Box::new(e))
    }
}

impl From<CompensateError<PredictError>> for JobError {
    fn from(e: CompensateError<PredictError>) -> Self {
        JobError::Compensate(Box::new(e))
    }
}

/// What a run did: the loop's record (also written to the job's `out`), the target's size and the
/// time taken.
pub struct Outcome {
    pub compensation: Compensation,
    pub size: [u32; 2],
    pub seconds: f64,
}

/// Runs `job` on `backend`, its renders reporting to `observer` (progress; a cancel stops the
/// loop after the iterations finished, which are written as any record); `on_iteration` sees
/// each iteration as it ends, with its number.
pub fn run(
    job: &Job,
    backend: &Backend,
    observer: Arc<dyn Observer + Send + Sync>,
    on_iteration: impl FnMut(usize, &Iteration),
) -> Result<Outcome, JobError> {
    run_on(job, Renderer::Backend(backend), observer, on_iteration)
}

/// [`run`], its predictions rendered by `renderer`.
pub fn run_on(
    job: &Job,
    renderer: Renderer<'_>,
    observer: Arc<dyn Observer + Send + Sync>,
    mut on_iteration: impl FnMut(usize, &Iteration),
) -> Result<Outcome, JobError> {
    let start = Instant::now();
    let invalid = |path: &Path, field, expected: &str, found: String| JobError::Invalid {
        path: path.to_path_buf(),
        field,
        expected: expected.into(),
        found,
    };
    // Everything a record refuses is refused before the first render.
    let slices = job.out.join("slices");
    if slices.join(crate::slices::MATERIALS_FILE).exists() || job.out.join(NAIVE_SLICES).exists() {
        return Err(invalid(
            &job.out,
            "the output folder",
            "a folder without a record's slices/materials.toml",
            slices.display().to_string(),
        ));
    }
    if !(job.colour_layers >= 1 && job.layers >= job.colour_layers) {
        return Err(invalid(
            &job.out,
            "layers",
            "at least one colour layer, and no more colour layers than layers",
            format!("{} layers, {} colour", job.layers, job.colour_layers),
        ));
    }
    if !(job.spp >= 1 && job.max_spp >= job.spp) {
        return Err(invalid(
            &job.out,
            "spp",
            "at least 1 sample per texel, and the most samples no fewer",
            format!("{} and at most {}", job.spp, job.max_spp),
        ));
    }
    if job.ior.is_some_and(|n| !(n.is_finite() && n > 0.0)) {
        return Err(invalid(
            &job.out,
            "ior",
            "a finite index of refraction above 0",
            format!("{:?}", job.ior),
        ));
    }
    let table = MaterialFile::read(&job.materials)?;
    let inks = Inks::find(&table.materials).map_err(|missing| {
        invalid(
            &job.materials,
            "materials",
            "materials named cyan, magenta, yellow, black and white (the inks)",
            format!("no material named {missing}"),
        )
    })?;
    let target = Target::read(&job.target)?;
    let setup = Setup {
        voxel_size: job.voxel_size.or(table.voxel_size).unwrap_or(VOXEL_SIZE),
        materials: table.materials,
        halftone: Halftone {
            layers: job.colour_layers,
            depth: job.layers,
            inks,
            seed: u64::from(job.seed),
        },
    };
    let renders = job.out.join(RENDERS);
    let mut predictor = match renderer {
        Renderer::Backend(backend) => RenderPredictor::new(backend, job.spp),
        Renderer::Elsewhere(render) => RenderPredictor::elsewhere(renders.clone(), render, job.spp),
    }
    .with_observer(observer);
    predictor.max_spp = job.max_spp;
    predictor.seed = job.seed;
    predictor.boundary = match job.ior {
        Some(int_ior) => volpt::scene_files::BsdfDesc::Dielectric {
            int_ior,
            ext_ior: 1.0,
        },
        None => volpt::scene_files::BsdfDesc::Null,
    };
    let mut k = 0;
    let compensation = compensate(
        &target.texels,
        target.size,
        &setup,
        &job.options,
        &mut predictor,
        |it| {
            on_iteration(k, it);
            k += 1;
        },
    );
    // The predictions' scene files are of no use after the loop, whatever its end.
    if renders.exists() {
        std::fs::remove_dir_all(&renders).map_err(|source| PrintError::Io {
            path: renders.clone(),
            source,
        })?;
    }
    let compensation = compensation?;
    write_record(&compensation, &target.texels, target.size, &job.out)?;
    // The kept print and the naive one as volpt scenes (for `volpt render` and the Mitsuba 3
    // export): the naive print is the first iteration's, halftoned again from its aims.
    let naive = print_for(
        &setup,
        &compensation.iterations[0].aims,
        target.size[0],
        target.size[1],
    )
    .map_err(|(field, expected, found)| invalid(&job.out, field, &expected, found))?;
    write_slices(&naive, &job.out.join(NAIVE_SLICES))?;
    for (name, print, slices) in [
        (PRINT_SCENE, &compensation.print, "slices"),
        (NAIVE_SCENE, &naive, NAIVE_SLICES),
    ] {
        let path = job.out.join(name);
        std::fs::write(&path, predictor.toml_scene(print, slices))
            .map_err(|source| PrintError::Io { path, source })?;
    }
    Ok(Outcome {
        compensation,
        size: target.size,
        seconds: start.elapsed().as_secs_f64(),
    })
}
