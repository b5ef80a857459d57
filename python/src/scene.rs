//! `volpt.load` and `volpt.Scene`: a loaded scene, its grids, and its renders.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict};
use volpt::{
    BackendKind, BackendOptions, Error, GpuOptions, Math, Part, RenderRequest, StrategyChoice,
};

use crate::backend::Backend;
use crate::convert::{
    describe, grid_shape, named, render_settings, sample_range, to_numpy, u32_from,
};
use crate::errors::{to_py, SettingsError};
use crate::film::Film;
use crate::observer::PyObserver;
use crate::params::SceneParameters;

/// `volpt.load`: the scene at `path` with `settings` over it and `params` as `-D` parameters.
#[pyfunction]
#[pyo3(signature = (path, settings, params))]
pub fn load(
    py: Python<'_>,
    path: PathBuf,
    settings: Option<&Bound<'_, PyDict>>,
    params: Vec<(String, String)>,
) -> PyResult<Scene> {
    let settings = render_settings(settings, params)?;
    let scene = py
        .allow_threads(|| volpt::Scene::load(&path, &settings))
        .map_err(to_py)?;
    Ok(Scene { inner: scene })
}

/// A loaded scene (see the stubs for the Python documentation).
#[pyclass(module = "volpt._volpt")]
pub struct Scene {
    pub inner: volpt::Scene,
}

/// `backend=` of a render: a [`Backend`] (whose options are its own), or a kind's name with
/// `strategy=` and `math=`, opened for this render.
pub(crate) enum Chosen<'py> {
    Given(PyRef<'py, Backend>),
    Opened(Box<Backend>),
}

impl std::ops::Deref for Chosen<'_> {
    type Target = Backend;

    fn deref(&self) -> &Backend {
        match self {
            Chosen::Given(backend) => backend,
            Chosen::Opened(backend) => backend,
        }
    }
}

pub(crate) fn choose<'py>(
    backend: &Bound<'py, PyAny>,
    strategy: Option<&str>,
    math: Option<&str>,
) -> PyResult<Chosen<'py>> {
    if let Ok(given) = backend.downcast::<Backend>() {
        if strategy.is_some() || math.is_some() {
            return Err(SettingsError::new_err(
                "render: strategy and math are a Backend's own options: give them to \
                 volpt.Backend(...), or name the backend (backend=\"cuda\")",
            ));
        }
        return Ok(Chosen::Given(given.borrow()));
    }
    let Ok(kind) = backend.extract::<String>() else {
        return Err(SettingsError::new_err(format!(
            "backend: expected {} or a volpt.Backend, found {}",
            volpt::names::expected::<BackendKind>(),
            describe(backend)
        )));
    };
    let options = BackendOptions {
        kind: named::<BackendKind>(&kind, "backend")?,
        gpu: GpuOptions {
            strategy: strategy
                .map(|name| named::<StrategyChoice>(name, "strategy"))
                .transpose()?,
            math: math.map(|name| named::<Math>(name, "math")).transpose()?,
            ..GpuOptions::default()
        },
    };
    Ok(Chosen::Opened(Box::new(Backend::open(
        backend.py(),
        options,
    )?)))
}

#[pymethods]
impl Scene {
    /// What `volpt info` prints, as a dict.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (key, value) in self.inner.info().fields {
            dict.set_item(key, value)?;
        }
        Ok(dict)
    }

    #[getter]
    fn params(slf: Bound<'_, Self>) -> SceneParameters {
        SceneParameters {
            scene: slf.unbind(),
        }
    }

    #[getter]
    fn spp(&self) -> u32 {
        self.inner.spp()
    }

    #[getter]
    fn seed(&self) -> u32 {
        self.inner.seed()
    }

    #[getter]
    fn resolution(&self) -> (u32, u32) {
        self.inner.resolution()
    }

    #[getter]
    fn variant(&self) -> String {
        self.inner.variant().to_string()
    }

    #[getter]
    fn fingerprint(&self) -> u64 {
        self.inner.fingerprint()
    }

    #[getter]
    fn source(&self) -> String {
        self.inner.source().to_owned()
    }

    /// The names of the medium's grids (`"density"`, `"albedo"`), which `grid` and `set_grid`
    /// take.
    #[getter]
    fn grids(&self) -> Vec<&'static str> {
        self.inner.grid_names()
    }

    /// Grid `name`'s values: a float32 array of shape (z, y, x), or (z, y, x, channels) for an
    /// RGB grid.
    fn grid<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let grid = self.inner.grid(name).map_err(to_py)?;
        let bytes: Vec<u8> = grid.data.iter().flat_map(|v| v.to_ne_bytes()).collect();
        to_numpy(py, &bytes, "float32", grid_shape(grid))
    }

    /// Replaces grid `name`'s values with `values` (an array of its shape, or flat in its order),
    /// as `volpt::Scene::set_grid`: the next render renders the scene as loaded with them.
    fn set_grid(&mut self, py: Python<'_>, name: &str, values: Bound<'_, PyAny>) -> PyResult<()> {
        let grid = self.inner.grid(name).map_err(to_py)?;
        let shape = grid_shape(grid);
        let wrong = |expected: String, found: String| {
            to_py(Error::Grid {
                grid: name.to_owned(),
                expected,
                found,
            })
        };
        let numpy = py.import("numpy")?;
        let array = numpy
            .call_method(
                "ascontiguousarray",
                (&values,),
                Some(&[("dtype", "float32")].into_py_dict(py)?),
            )
            .map_err(|_| wrong("an array of numbers".into(), describe(&values)))?;
        let found: Vec<usize> = array.getattr("shape")?.extract()?;
        if found.len() > 1 && found != shape {
            return Err(wrong(
                format!("an array of shape {shape:?} (z, y, x[, channels]) or flat"),
                format!("an array of shape {found:?}"),
            ));
        }
        let bytes: Vec<u8> = array.call_method0("tobytes")?.extract()?;
        let values: Vec<f32> = bytes
            .chunks_exact(4)
            .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        let scene = &mut self.inner;
        py.allow_threads(|| scene.set_grid(name, values))
            .map_err(to_py)
    }

    fn __repr__(&self) -> String {
        let (w, h) = self.inner.resolution();
        format!(
            "volpt.Scene({:?}, {w}x{h}, {} spp, variant {})",
            self.inner.source(),
            self.inner.spp(),
            self.inner.variant()
        )
    }

    /// Renders samples `samples` (default `range(0, spp)`) of every pixel; see the stubs.
    #[pyo3(signature = (*, spp=None, seed=None, samples=None, backend=None, strategy=None, math=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn render(
        slf: Bound<'_, Self>,
        spp: Option<Bound<'_, PyAny>>,
        seed: Option<Bound<'_, PyAny>>,
        samples: Option<Bound<'_, PyAny>>,
        backend: Option<Bound<'_, PyAny>>,
        strategy: Option<&str>,
        math: Option<&str>,
        progress: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Film> {
        let py = slf.py();
        let spp = u32_from(spp, "spp", 1)?;
        let seed = u32_from(seed, "seed", 0)?;
        let samples = match (samples, spp) {
            (Some(_), Some(_)) => {
                return Err(SettingsError::new_err(
                    "render: give spp (samples 0 to spp) or samples (a range), not both",
                ))
            }
            (Some(range), None) => Some(sample_range(&range)?),
            (None, _) => None,
        };
        let backend = match backend {
            Some(backend) => backend,
            None => BackendKind::Cpu.to_string().into_pyobject(py)?.into_any(),
        };
        let backend = choose(&backend, strategy, math)?;
        let observer = PyObserver::new(progress, backend.inner.kind())?;

        // Renders only read the scene: threads render one scene at once (a parameter change
        // waits for none of them, and is refused while one runs).
        let this = slf.try_borrow().map_err(|_| {
            SettingsError::new_err("render: the scene is being changed by another thread")
        })?;
        let scene = &this.inner;
        let request = RenderRequest {
            samples: samples.unwrap_or(0..spp.unwrap_or(scene.spp())),
            seed,
            ..RenderRequest::default()
        };
        let inner = &backend.inner;
        let result = py.allow_threads(|| {
            let mut film = scene.film();
            let rendered = inner.render(scene, &mut film, &request, &observer)?;
            let fingerprint = inner.fingerprint(scene, &request)?;
            Ok::<_, volpt::Error>((film, rendered, fingerprint))
        });
        let part_seed = request.seed.unwrap_or(scene.seed());
        drop(this);
        if let Some(error) = observer.take_error() {
            return Err(error);
        }
        let (film, rendered, fingerprint) = result.map_err(to_py)?;
        observer.done(py)?;
        Ok(Film {
            part: Part {
                fingerprint,
                seed: part_seed,
                samples: rendered.samples,
                film,
            },
            elapsed: rendered.stats.elapsed.as_secs_f64(),
            paths: rendered.stats.counters.paths,
            notes: observer.into_notes(),
        })
    }
}
