//! Where the GPU reads volumes from: `--volume-memory`, `--device-memory-budget`, `--bricked`
//! (docs/out-of-core.md).

use clap::Args;
use volpt::VolumeMemory;

#[derive(Args, Clone, Debug, Default)]
pub struct VolumeArgs {
    /// Where the GPU reads grids from: device (copied to GPU memory), zerocopy (page-locked host
    /// memory mapped into the GPU, read across the bus), managed (the part that fits the budget
    /// prefetched to the GPU, the rest read from host memory) or auto (default: on the GPU while
    /// the grids fit the budget, zero-copy beyond).
    #[arg(long, value_name = "device|zerocopy|managed|auto")]
    pub volume_memory: Option<VolumeMemory>,
    /// The most GPU memory the grids may take, in bytes or with a K, M, G suffix (default: what
    /// the GPU has free, less 512M). Never more than the GPU has free.
    #[arg(long, value_name = "BYTES", value_parser = crate::parse_bytes)]
    pub device_memory_budget: Option<u64>,
    /// Store grids on the GPU in 8x8x8 bricks: fewer, fuller transfers when the GPU reads them
    /// across the bus (the image is the same bit for bit).
    #[arg(long)]
    pub bricked: bool,
}
