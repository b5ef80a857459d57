use cudarc::driver::DriverError;
use thiserror::Error;

/// What can go wrong placing a volume; every out-of-memory case says how much was asked for and
/// what to try instead.
#[derive(Debug, Error)]
pub enum GpuMemError {
    #[error(
        "the GPU has no room for a volume of {} (--volume-memory device): use \
         --volume-memory auto, zerocopy or managed to read it from host memory",
        crate::policy::human_bytes(*.bytes)
    )]
    OutOfDeviceMemory {
        bytes: u64,
        #[source]
        source: DriverError,
    },
    #[error(
        "a volume of {} does not fit the device memory budget ({} left of \
         --device-memory-budget {}) with --volume-memory device: use --volume-memory auto, \
         zerocopy or managed, or a larger budget",
        crate::policy::human_bytes(*.bytes),
        crate::policy::human_bytes(*.left),
        crate::policy::human_bytes(*.budget)
    )]
    OverBudget { bytes: u64, left: u64, budget: u64 },
    #[error(
        "cannot page-lock {} of host memory for a volume read by the GPU (the system's \
         pinned memory, `ulimit -l` or RAM is exhausted): free memory, or use \
         --volume-memory managed",
        crate::policy::human_bytes(*.bytes)
    )]
    OutOfPinnedMemory {
        bytes: u64,
        #[source]
        source: DriverError,
    },
    #[error(
        "cannot allocate {} of managed memory for a volume: free host memory, or use \
         --volume-memory zerocopy",
        crate::policy::human_bytes(*.bytes)
    )]
    OutOfManagedMemory {
        bytes: u64,
        #[source]
        source: DriverError,
    },
    #[error(
        "cannot allocate {} of host memory to rearrange a volume into bricks",
        crate::policy::human_bytes(*.bytes)
    )]
    OutOfHostMemory { bytes: u64 },
    #[error(
        "a grid texture of {} does not fit in device memory ({} left of a budget of {}): \
         textures cannot be read from host memory; use --lookup trilinear (with --volume-memory \
         auto, zerocopy or managed for volumes larger than the GPU) or a larger \
         --device-memory-budget",
        crate::policy::human_bytes(*.bytes),
        crate::policy::human_bytes(*.left),
        crate::policy::human_bytes(*.budget)
    )]
    TextureOverBudget { bytes: u64, left: u64, budget: u64 },
    #[error(
        "the GPU has no room for a grid texture of {}: textures cannot be read from host memory; \
         use --lookup trilinear (with --volume-memory auto, zerocopy or managed for volumes \
         larger than the GPU)",
        crate::policy::human_bytes(*.bytes)
    )]
    TextureOutOfMemory {
        bytes: u64,
        #[source]
        source: DriverError,
    },
    #[error(
        "--lookup texture keeps grids in device memory, but --volume-memory {memory} asks for host \
         memory: drop one of them"
    )]
    TextureInHostMemory { memory: crate::policy::VolumeMemory },
    #[error(
        "a sparse volume whose box has {bricks} bricks of 8^3 samples: the GPU reads a table of \
         one entry per brick, at most {max} (a box of 5120^3 samples); render it on the CPU \
         (--backend cpu), which reads its two-level table"
    )]
    SparseTableTooLarge { bricks: u64, max: u64 },
    #[error("CUDA driver call failed while {doing} ({} volume): {source}", crate::policy::human_bytes(*.bytes))]
    Driver {
        doing: &'static str,
        bytes: u64,
        #[source]
        source: DriverError,
    },
}

impl GpuMemError {
    /// Whether the driver said it ran out of memory (device or host).
    pub(crate) fn is_out_of_memory(source: &DriverError) -> bool {
        source.0 == cudarc::driver::sys::CUresult::CUDA_ERROR_OUT_OF_MEMORY
    }
}
