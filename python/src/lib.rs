//! `volpt._volpt`: the Python extension module over the library facade (`volpt`), one class a
//! file:
//!
//! - [`errors`]: the exceptions (`volpt.errors`' classes), one per kind of library error.
//! - [`convert`]: Python values as the library's (integers, named choices, sample ranges,
//!   `volpt.load`'s settings) and arrays as numpy's.
//! - [`scene`]: `volpt.load` and `volpt.Scene` (grids, renders).
//! - [`params`]: `scene.params`, the parameters that change between renders, as a mapping.
//! - [`backend`]: `volpt.Backend`, the CPU or GPUs with all their options, opened once.
//! - [`film`]: `volpt.Film` (images, files, bytes, pickling), `volpt.merge`, `volpt.read_exr`.
//! - [`observer`]: progress, Ctrl-C and notes while a render runs with the GIL released.
//! - [`print`]: `volpt.compensate_print`, the scattering compensation of a colour 3D print.
//!
//! The package around it (`python/volpt/__init__.py`) adds `volpt.load`'s keyword parameters and
//! the exception classes; the stubs (`python/volpt/_volpt.pyi`) document every class and method.

mod backend;
mod convert;
mod errors;
mod film;
mod observer;
mod params;
mod print;
mod scene;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use volpt::{StrategyChoice, PARAMS};

#[pymodule]
fn _volpt(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(scene::load, m)?)?;
    m.add_function(wrap_pyfunction!(film::merge, m)?)?;
    m.add_function(wrap_pyfunction!(film::read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(print::compensate_print, m)?)?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<params::SceneParameters>()?;
    m.add_class::<film::Film>()?;
    m.add_class::<backend::Backend>()?;
    let params = PyDict::new(m.py());
    for (key, what) in PARAMS {
        params.set_item(key, what)?;
    }
    m.add("PARAMS", params)?;
    m.add("SETTINGS", PyTuple::new(m.py(), convert::SETTINGS)?)?;
    m.add(
        "STRATEGIES",
        PyTuple::new(m.py(), volpt::names::names::<StrategyChoice>())?,
    )?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
