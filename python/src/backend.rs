//! `volpt.Backend`: the CPU or GPUs with every option `volpt render` has (strategy, math,
//! register cap, refill threshold, tiles, volume memory, device memory budget, bricked grids,
//! several GPUs), opened once and reused by the renders given it: a GPU's kernels load once,
//! and `auto`'s calibrations are kept per scene.

use pyo3::prelude::*;
use pyo3::types::PyList;
use volpt::{BackendKind, BackendOptions, GpuOptions, Gpus, Math, StrategyChoice, VolumeMemory};

use crate::convert::{describe, int_in, named, u32_from};
use crate::errors::{to_py, SettingsError};

/// An opened backend (see the stubs for the Python documentation).
#[pyclass(module = "volpt._volpt", frozen)]
pub struct Backend {
    pub inner: volpt::Backend,
    options: BackendOptions,
}

impl Backend {
    /// Opens the backend of `options`, the GIL released (a GPU's kernels load meanwhile).
    pub fn open(py: Python<'_>, options: BackendOptions) -> PyResult<Self> {
        let inner = py
            .allow_threads(|| volpt::Backend::open(&options))
            .map_err(to_py)?;
        Ok(Self { inner, options })
    }

    /// The backend of a caller who names none: a GPU where one is usable, else the CPU
    /// (`volpt::Backend::open_preferred`), and why.
    pub fn preferred(py: Python<'_>) -> PyResult<(Self, String)> {
        let gpu = volpt::GpuOptions::default();
        let preferred = py
            .allow_threads(|| volpt::Backend::open_preferred(&gpu))
            .map_err(to_py)?;
        let options = BackendOptions {
            kind: preferred.backend.kind(),
            gpu,
        };
        Ok((
            Self {
                inner: preferred.backend,
                options,
            },
            preferred.reason,
        ))
    }
}

/// `gpus=`: `"all"`, one ordinal, or a sequence of them.
fn gpus_from(value: &Bound<'_, PyAny>) -> PyResult<Gpus> {
    let wrong = || {
        SettingsError::new_err(format!(
            "gpus: expected \"all\", a GPU's number (0 to 63) or a sequence of them, found {}",
            describe(value)
        ))
    };
    if let Ok(text) = value.extract::<String>() {
        return if text == "all" {
            Ok(Gpus::All)
        } else {
            Err(wrong())
        };
    }
    let ordinals: Vec<Bound<'_, PyAny>> = if value.extract::<i64>().is_ok() {
        vec![value.clone()]
    } else {
        value.extract().map_err(|_| wrong())?
    };
    let mut mask = 0u64;
    for ordinal in &ordinals {
        mask |= 1 << int_in(ordinal, "gpus", 0, 63).map_err(|_| wrong())?;
    }
    Ok(Gpus::List(mask))
}

#[pymethods]
impl Backend {
    #[new]
    #[pyo3(signature = (
        kind="cpu", *, strategy=None, math=None, max_registers=None, refill_at=None, tiles=None,
        volume_memory=None, device_memory_budget=None, bricked=false, gpus=None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        kind: &str,
        strategy: Option<&str>,
        math: Option<&str>,
        max_registers: Option<Bound<'_, PyAny>>,
        refill_at: Option<Bound<'_, PyAny>>,
        tiles: Option<Bound<'_, PyAny>>,
        volume_memory: Option<&str>,
        device_memory_budget: Option<Bound<'_, PyAny>>,
        bricked: bool,
        gpus: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let tiles = match tiles {
            None => None,
            Some(value) => {
                let (c, r) = value
                    .extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>()
                    .map_err(|_| {
                        SettingsError::new_err(format!(
                            "tiles: expected (columns, rows), found {}",
                            describe(&value)
                        ))
                    })?;
                Some([
                    u32_from(Some(c), "tiles", 0)?.unwrap_or_default(),
                    u32_from(Some(r), "tiles", 0)?.unwrap_or_default(),
                ])
            }
        };
        let device_memory_budget = device_memory_budget
            .map(|v| int_in(&v, "device_memory_budget", 1, i64::MAX).map(|v| v as u64))
            .transpose()?;
        let options = BackendOptions {
            kind: named::<BackendKind>(kind, "kind")?,
            gpu: GpuOptions {
                strategy: strategy
                    .map(|s| named::<StrategyChoice>(s, "strategy"))
                    .transpose()?,
                math: math.map(|m| named::<Math>(m, "math")).transpose()?,
                // Their bounds are the library's to check (volpt::MAX_REGISTERS, REFILL_AT).
                max_registers: u32_from(max_registers, "max_registers", 0)?,
                refill_at: u32_from(refill_at, "refill_at", 0)?,
                tiles,
                volume_memory: volume_memory
                    .map(|v| named::<VolumeMemory>(v, "volume_memory"))
                    .transpose()?,
                device_memory_budget,
                bricked,
                gpus: gpus.map(|g| gpus_from(&g)).transpose()?.unwrap_or_default(),
            },
        };
        Self::open(py, options)
    }

    /// `"cpu"` or `"cuda"`.
    #[getter]
    fn kind(&self) -> &'static str {
        volpt::Named::name(self.inner.kind())
    }

    /// The devices that render together: 1 but for several GPUs.
    #[getter]
    fn devices(&self) -> usize {
        self.inner.devices()
    }

    /// The device's name (the CPU's, or the GPU's).
    #[getter]
    fn device_name(&self) -> String {
        self.inner.device_name()
    }

    /// The strategy asked for (`"auto"` or a fixed one); `None` on the CPU.
    #[getter]
    fn strategy(&self) -> Option<String> {
        self.inner.strategy().map(|s| s.to_string())
    }

    /// The GPU's math (`"fast"`, `"exact"`); `None` on the CPU.
    #[getter]
    fn math(&self) -> Option<&'static str> {
        self.inner.math().map(volpt::Named::name)
    }

    /// The GPUs' numbers the backend was asked for: `None` (GPU 0), `"all"` or a list.
    #[getter]
    fn gpus<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        Ok(match self.options.gpu.gpus {
            Gpus::First => None,
            Gpus::All => Some("all".into_pyobject(py)?.into_any()),
            Gpus::List(mask) => {
                let ordinals: Vec<u32> = (0..64).filter(|i| mask & (1 << i) != 0).collect();
                Some(PyList::new(py, ordinals)?.into_any())
            }
        })
    }

    fn __repr__(&self) -> String {
        let mut text = format!("volpt.Backend({:?}", self.kind());
        if let Some(strategy) = self.strategy() {
            text += &format!(", strategy={strategy:?}");
        }
        if let Some(math) = self.math() {
            text += &format!(", math={math:?}");
        }
        text + ")"
    }
}
