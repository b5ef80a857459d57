//! The backend of a caller who names none, where a GPU is the better default (a printing
//! compensation: hundreds of renders of one scene): a GPU where one is usable, else the CPU, with
//! the reason, so the front end can say which it chose and why.
//!
//! The rule ([`preferred_kind`]): a GPU option asked for (`--gpus`, a strategy, ...) means the GPU,
//! and a GPU that cannot open is then an error, as with `--backend cuda`; otherwise the GPU if this
//! build carries kernels and the driver sees a GPU, else the CPU. A GPU that the probe found but
//! that does not open falls back to the CPU too ([`Backend::open_preferred`]), saying why.

use crate::backend::{Backend, BackendKind, BackendOptions, GpuOptions};
use crate::Error;

/// What the machine offers, as [`preferred_kind`] reads it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum GpuProbe {
    /// This build carries no GPU kernels (`cargo xtask ptx` did not run before it was built).
    NoKernels,
    /// No CUDA driver, or the driver failed to count the GPUs: its message.
    NoDriver(String),
    /// The driver sees this many GPUs (0 included).
    Gpus(usize),
}

impl GpuProbe {
    /// This machine's.
    pub fn now() -> Self {
        if !volpt_cuda::has_kernels() {
            return GpuProbe::NoKernels;
        }
        match volpt_cuda::device_count() {
            Ok(n) => GpuProbe::Gpus(n),
            Err(e) => GpuProbe::NoDriver(e.to_string()),
        }
    }
}

/// Which backend a caller who names none gets, and why (one clause, for a note such as
/// "rendering on the CPU: no CUDA driver").
pub fn preferred_kind(probe: &GpuProbe, gpu: &GpuOptions) -> (BackendKind, String) {
    if *gpu != GpuOptions::default() {
        return (BackendKind::Cuda, "GPU options were given".into());
    }
    match probe {
        GpuProbe::NoKernels => (BackendKind::Cpu, "this build carries no GPU kernels".into()),
        GpuProbe::NoDriver(why) => (BackendKind::Cpu, format!("no GPU is usable ({why})")),
        GpuProbe::Gpus(0) => (BackendKind::Cpu, "the CUDA driver sees no GPU".into()),
        GpuProbe::Gpus(n) => (
            BackendKind::Cuda,
            format!("a GPU is present ({n} seen by the driver)"),
        ),
    }
}

/// A backend opened by [`Backend::open_preferred`], with why it is that one.
pub struct Preferred {
    pub backend: Backend,
    pub reason: String,
}

impl Backend {
    /// The backend of a caller who names none (see the module docs): the GPU with `gpu`'s options
    /// where one is usable, else the CPU. Errors only where GPU options were given and the GPU
    /// does not open.
    pub fn open_preferred(gpu: &GpuOptions) -> Result<Preferred, Error> {
        Self::open_preferred_with(&GpuProbe::now(), gpu)
    }

    /// [`Backend::open_preferred`] for a given probe (a test's).
    #[doc(hidden)]
    pub fn open_preferred_with(probe: &GpuProbe, gpu: &GpuOptions) -> Result<Preferred, Error> {
        let (kind, reason) = preferred_kind(probe, gpu);
        let asked = *gpu != GpuOptions::default();
        match Backend::open(&BackendOptions { kind, gpu: *gpu }) {
            Ok(backend) => Ok(Preferred { backend, reason }),
            Err(e) if kind == BackendKind::Cuda && !asked => Ok(Preferred {
                backend: Backend::cpu(),
                reason: format!("the GPU did not open ({e})"),
            }),
            Err(e) => Err(e),
        }
    }
}
