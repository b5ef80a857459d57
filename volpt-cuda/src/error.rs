use cudarc::driver::DriverError;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum CudaError {
    #[error(
        "no CUDA driver found (libcuda.so could not be loaded): --backend cuda needs an NVIDIA GPU \
         and its driver; use --backend cpu"
    )]
    NoDriver,
    #[error(
        "this volpt was built without the GPU's {0} kernels: run `cargo xtask ptx` (it builds both \
         and installs the rust-src component if needed), then rebuild volpt"
    )]
    NoKernels(volpt_device::Math),
    #[error(
        "this volpt's embedded {math} kernels cannot be read ({source}): rebuild it (`cargo xtask \
         ptx`, then `cargo build`)"
    )]
    CorruptKernels {
        math: volpt_device::Math,
        source: crate::kernels::PackError,
    },
    #[error("cannot read the kernels' PTX from {path} (VOLPT_PTX): {source}")]
    PtxFile {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error(
        "the GPU kernels have no entry point `{0}`: the PTX is out of date (run `cargo xtask ptx`), \
         or no kernels crate exports this scene type (`volpt_device::export_kernels!`)"
    )]
    MissingKernel(String),
    #[error(transparent)]
    Empty(#[from] volpt_film::NothingToRender),
    #[error(
        "the GPU kernels trace lights besides the environment or a triangle-mesh boundary, not \
         both: this scene renders on the CPU (--backend cpu)"
    )]
    LightsAndMesh,
    /// A mesh boundary whose surface scatters about interpolated vertex normals: the kernels
    /// refract at each triangle's own normal.
    #[error(
        "the GPU kernels refract at each triangle's own normal, and this mesh's surface scatters \
         about interpolated vertex normals (Mitsuba's default for an obj or ply): this scene \
         renders on the CPU (--backend cpu), or on the GPU with face_normals=\"true\" on the \
         shape"
    )]
    ShadingNormals,
    /// A scene that needs a kernel set ([`volpt_device::KernelSet`]) rendered with a strategy
    /// that set has no kernels for.
    #[error(
        "the GPU kernels for a scene with {what} are those of {strategies} only, not {strategy}: \
         choose one of those (--strategy), or auto"
    )]
    SetStrategy {
        what: &'static str,
        strategy: volpt_device::Strategy,
        strategies: String,
    },
    /// A scene that needs a kernel set of a variant the set does not cover.
    #[error(
        "the GPU kernels for a scene with {what} do not cover this scene's parts ({variant}): it \
         renders on the CPU (--backend cpu)"
    )]
    SetVariant { what: &'static str, variant: String },
    #[error(transparent)]
    Volume(#[from] volpt_gpu_mem::GpuMemError),
    #[error("CUDA driver call failed while {doing}: {source}")]
    Driver {
        doing: &'static str,
        source: DriverError,
    },
}

/// Attaches what volpt was doing to a driver error.
pub(crate) trait Doing<T> {
    fn doing(self, doing: &'static str) -> Result<T, CudaError>;
}

impl<T> Doing<T> for Result<T, DriverError> {
    fn doing(self, doing: &'static str) -> Result<T, CudaError> {
        self.map_err(|source| CudaError::Driver { doing, source })
    }
}
