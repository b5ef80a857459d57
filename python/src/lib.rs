//! `volpt._volpt`: the Python extension module over the library facade (`volpt`).
//!
//! The package around it (`python/volpt/__init__.py`) adds `volpt.load`'s keyword parameters and
//! the exception classes; the stubs (`python/volpt/_volpt.pyi`) document every class and method.
//!
//! Rendering releases the GIL. Between chunks of samples (about [`CPU_CHECK_EVERY`] of work each)
//! the render's own thread takes the GIL back briefly to run Python's signal handlers (Ctrl-C
//! raises `KeyboardInterrupt` there) and the progress callback; the worker threads never touch
//! Python, so a render cannot deadlock against the interpreter.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyByteArray, PyDict, PyList, PyRange, PyTuple, PyType};
use volpt::film::checkpoint::Checkpoint;
use volpt::{
    Backend, BackendKind, BackendOptions, Error, GpuOptions, Image, Math, Named, Observer,
    ParamValue, Part, RenderRequest, RenderSettings, StrategyChoice, PARAMS,
};

/// How much CPU rendering passes between looks at Ctrl-C and the progress callback.
const CPU_CHECK_EVERY: Duration = Duration::from_millis(100);
/// The same on a GPU: each chunk is a launch with its tail, so chunks are longer there.
const CUDA_CHECK_EVERY: Duration = Duration::from_millis(500);

// ---------------------------------------------------------------------------------------------
// Errors

/// The Python exception for `error`, of the class `volpt.errors` defines for its kind, with the
/// Rust message (file, field, expected, found).
fn to_py(error: Error) -> PyErr {
    let class = match &error {
        Error::Scene(volpt::scene_files::SceneError::Io { error, .. })
            if error.kind() == std::io::ErrorKind::NotFound =>
        {
            "SceneNotFoundError"
        }
        Error::Scene(_) => "SceneError",
        Error::Settings(_) | Error::Setting { .. } => "SettingsError",
        Error::UnknownParam { .. } => "UnknownParamError",
        Error::Param { .. } => "ParamError",
        Error::Grid { .. } => "GridError",
        Error::Cpu(_) | Error::Cuda(_) => "RenderError",
        Error::Checkpoint(_) | Error::FilmFile(_) => "CheckpointError",
        Error::Films(_) => "MergeError",
        Error::Image(_) => "ImageError",
    };
    let text = match &error {
        // The library's key is a keyword argument's or a settings key's name: spelled as
        // Python's settings mapping takes it.
        Error::Setting {
            key,
            expected,
            found,
        } => format!("settings[{key:?}]: expected {expected}, found {found}"),
        _ => message(&error),
    };
    raise(class, text)
}

/// The error's message with the causes its own text does not already say.
fn message(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        let cause_text = cause.to_string();
        if !text.contains(&cause_text) {
            text = format!("{text}: {cause_text}");
        }
        source = cause.source();
    }
    text
}

/// An exception of class `volpt.errors.<class>` with `text`.
fn raise(class: &str, text: String) -> PyErr {
    Python::with_gil(|py| {
        let class = py
            .import("volpt.errors")
            .and_then(|m| m.getattr(class))
            .and_then(|c| c.downcast_into::<PyType>().map_err(PyErr::from));
        match class {
            Ok(class) => PyErr::from_type(class, text),
            Err(e) => e,
        }
    })
}

fn settings_error(text: String) -> PyErr {
    raise("SettingsError", text)
}

// ---------------------------------------------------------------------------------------------
// Loading

/// An integer argument in `lo..=hi`, or a `SettingsError` naming `what`.
fn int_in(value: &Bound<'_, PyAny>, what: &str, lo: i64, hi: i64) -> PyResult<i64> {
    let found = describe(value);
    let wrong = || {
        settings_error(format!(
            "{what}: expected an integer from {lo} to {hi}, found {found}"
        ))
    };
    if value.is_instance_of::<pyo3::types::PyBool>() {
        return Err(wrong());
    }
    match value.extract::<i64>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        _ => Err(wrong()),
    }
}

/// A short description of a Python value for messages: its type and repr.
fn describe(value: &Bound<'_, PyAny>) -> String {
    let ty = value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into());
    let repr = value
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "?".into());
    let repr = if repr.chars().count() > 60 {
        format!("{}...", repr.chars().take(57).collect::<String>())
    } else {
        repr
    };
    format!("{ty} {repr}")
}

/// A name of one of the library's choices ([`Named`]), or a `SettingsError` naming `what` and
/// the names (the library's words: `volpt::names`).
fn choice<T: Named>(value: &Bound<'_, PyAny>, what: &str) -> PyResult<T> {
    let name = value.extract::<String>().ok();
    name.and_then(|s| volpt::names::parse::<T>(&s).ok())
        .ok_or_else(|| {
            settings_error(format!(
                "{what}: expected {}, found {}",
                volpt::names::expected::<T>(),
                describe(value)
            ))
        })
}

/// The choice `name` names ([`Named`]), or a `SettingsError` naming `what` and the names.
fn named<T: Named>(name: &str, what: &str) -> PyResult<T> {
    volpt::names::parse::<T>(name).map_err(|_| {
        settings_error(format!(
            "{what}: expected {}, found {name:?}",
            volpt::names::expected::<T>()
        ))
    })
}

const SETTINGS: &[&str] = &[
    "spp",
    "seed",
    "resolution",
    "max_depth",
    "rr_depth",
    "tracking",
    "majorant_resolution",
    "estimator",
    "lookup",
    "roulette",
    "effects",
    "threads",
];

/// `volpt.load`'s `settings` mapping as the library's [`RenderSettings`] (the `volpt render` flags
/// of the same names).
fn render_settings(
    settings: Option<&Bound<'_, PyDict>>,
    params: Vec<(String, String)>,
) -> PyResult<RenderSettings> {
    let mut out = RenderSettings {
        params,
        ..RenderSettings::default()
    };
    let Some(settings) = settings else {
        return Ok(out);
    };
    let u32_max = i64::from(u32::MAX);
    let depth = |v: i64| u32::try_from(v).ok();
    for (key, value) in settings.iter() {
        let key: String = key.extract().map_err(|_| {
            settings_error(format!(
                "settings: keys are strings, found {}",
                describe(&key)
            ))
        })?;
        let what = format!("settings[{key:?}]");
        let what = what.as_str();
        match key.as_str() {
            "spp" => out.spp = Some(int_in(&value, what, 1, u32_max)? as u32),
            "seed" => out.seed = int_in(&value, what, 0, u32_max)? as u32,
            "resolution" => {
                let pair = value
                    .extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>()
                    .map_err(|_| {
                        settings_error(format!(
                            "{what}: expected (width, height), found {}",
                            describe(&value)
                        ))
                    })?;
                out.resolution = Some((
                    int_in(&pair.0, what, 1, u32_max)? as u32,
                    int_in(&pair.1, what, 1, u32_max)? as u32,
                ));
            }
            "max_depth" => out.max_depth = Some(depth(int_in(&value, what, -1, u32_max)?)),
            "rr_depth" => out.rr_depth = Some(depth(int_in(&value, what, -1, u32_max)?)),
            "tracking" => out.tracking = Some(choice(&value, what)?),
            "majorant_resolution" => {
                // Its range is the library's to check (volpt::MAJORANT_RESOLUTION).
                out.majorant_resolution = Some(int_in(&value, what, 0, u32_max)? as u32)
            }
            "estimator" => out.estimator = Some(choice(&value, what)?),
            "lookup" => out.lookup = Some(choice(&value, what)?),
            "roulette" => out.roulette = Some(choice(&value, what)?),
            "effects" => out.effects = choice(&value, what)?,
            "threads" => out.threads = Some(int_in(&value, what, 1, u32_max)? as usize),
            _ => {
                return Err(settings_error(format!(
                    "settings: expected one of {}, found {key:?}",
                    SETTINGS.join(", ")
                )))
            }
        }
    }
    Ok(out)
}

/// `volpt.load`: the scene at `path` with `settings` over it and `params` as `-D` parameters.
#[pyfunction]
#[pyo3(signature = (path, settings, params))]
fn load(
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

// ---------------------------------------------------------------------------------------------
// Scene and its parameters

/// A loaded scene (see the stubs for the Python documentation).
#[pyclass(module = "volpt._volpt")]
struct Scene {
    inner: volpt::Scene,
}

/// A parameter's value as Python sees it: an int, a float or a tuple of three floats.
fn param_to_py(py: Python<'_>, value: ParamValue) -> PyResult<PyObject> {
    Ok(match value {
        ParamValue::Int(v) => v.into_pyobject(py)?.into_any().unbind(),
        ParamValue::Float(v) => f64::from(v).into_pyobject(py)?.into_any().unbind(),
        ParamValue::Rgb(v) | ParamValue::Vec3(v) => {
            PyTuple::new(py, v.map(f64::from))?.into_any().unbind()
        }
    })
}

/// A Python value as a parameter value: an int (not a bool), a real number, or three numbers.
fn param_from_py(key: &str, value: &Bound<'_, PyAny>) -> PyResult<ParamValue> {
    let wrong = || {
        let expected = PARAMS
            .iter()
            .find(|(k, _)| *k == key)
            .map_or("a value", |(_, d)| *d);
        raise(
            "ParamError",
            format!(
                "parameter {key}: expected {expected}, found {}",
                describe(value)
            ),
        )
    };
    if value.is_instance_of::<pyo3::types::PyBool>()
        || value.is_instance_of::<pyo3::types::PyString>()
    {
        return Err(wrong());
    }
    // Integers: Python's and numpy's (an array has `__index__` too, and fails it).
    if value.hasattr("__index__")? {
        if let Ok(v) = value.extract::<i64>() {
            return Ok(ParamValue::Int(v));
        }
    }
    if let Ok(v) = value.extract::<f64>() {
        return Ok(ParamValue::Float(v as f32));
    }
    match value.extract::<Vec<f64>>() {
        Ok(v) if v.len() == 3 => Ok(ParamValue::Vec3([v[0] as f32, v[1] as f32, v[2] as f32])),
        _ => Err(wrong()),
    }
}

/// `scene.params[key]`: the value, or `UnknownParamError` (a `KeyError`).
fn get_param(py: Python<'_>, scene: &volpt::Scene, key: &str) -> PyResult<PyObject> {
    let value = scene.get(key).map_err(to_py)?;
    param_to_py(py, value)
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
        let buffer = PyByteArray::new(py, &bytes);
        py.import("numpy")?
            .call_method1("frombuffer", (buffer, "float32"))?
            .call_method1("reshape", (grid_shape(grid),))
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
    #[pyo3(signature = (*, spp=None, seed=None, samples=None, backend="cpu", strategy=None, math=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn render(
        slf: Bound<'_, Self>,
        spp: Option<Bound<'_, PyAny>>,
        seed: Option<Bound<'_, PyAny>>,
        samples: Option<Bound<'_, PyAny>>,
        backend: &str,
        strategy: Option<&str>,
        math: Option<&str>,
        progress: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Film> {
        let py = slf.py();
        let u32_max = i64::from(u32::MAX);
        let spp = spp
            .map(|v| int_in(&v, "spp", 1, u32_max).map(|v| v as u32))
            .transpose()?;
        let seed = seed
            .map(|v| int_in(&v, "seed", 0, u32_max).map(|v| v as u32))
            .transpose()?;
        let samples = match (samples, spp) {
            (Some(_), Some(_)) => {
                return Err(settings_error(
                    "render: give spp (samples 0 to spp) or samples (a range), not both".into(),
                ))
            }
            (Some(range), None) => Some(sample_range(&range)?),
            (None, _) => None,
        };
        let options = backend_options(backend, strategy, math)?;
        let callback = match progress {
            None => None,
            Some(p) if p.is_instance_of::<pyo3::types::PyBool>() => {
                if p.extract::<bool>()? {
                    Some(
                        py.import("volpt._progress")?
                            .getattr("Bar")?
                            .call0()?
                            .unbind(),
                    )
                } else {
                    None
                }
            }
            Some(p) if p.is_callable() => Some(p.unbind()),
            Some(p) => {
                return Err(PyTypeError::new_err(format!(
                    "progress: expected a bool or a callable(done, total), found {}",
                    describe(&p)
                )))
            }
        };
        let backend = open_backend(py, &options)?;

        // Renders only read the scene: threads render one scene at once (a parameter change
        // waits for none of them, and is refused while one runs).
        let this = slf.try_borrow().map_err(|_| {
            settings_error("render: the scene is being changed by another thread".into())
        })?;
        let scene = &this.inner;
        let request = RenderRequest {
            samples: samples.unwrap_or(0..spp.unwrap_or(scene.spp())),
            seed,
            ..RenderRequest::default()
        };
        let observer = PyObserver {
            callback,
            done: AtomicU64::new(0),
            total: AtomicU64::new(0),
            error: Mutex::new(None),
            notes: Mutex::new(Vec::new()),
            every: match options.kind {
                BackendKind::Cpu => CPU_CHECK_EVERY,
                BackendKind::Cuda => CUDA_CHECK_EVERY,
            },
        };
        let result = py.allow_threads(|| {
            let mut film = scene.film();
            let rendered = backend.render(scene, &mut film, &request, &observer)?;
            let fingerprint = backend.fingerprint(scene, &request)?;
            Ok::<_, volpt::Error>((film, rendered, fingerprint))
        });
        let part_seed = request.seed.unwrap_or(scene.seed());
        drop(this);
        if let Some(error) = observer.error.lock().expect("not poisoned").take() {
            return Err(error);
        }
        let (film, rendered, fingerprint) = result.map_err(to_py)?;
        if let Some(callback) = &observer.callback {
            let total = observer.total.load(Ordering::Relaxed).max(1);
            callback.call1(py, (total, total))?;
        }
        Ok(Film {
            part: Part {
                fingerprint,
                seed: part_seed,
                samples: rendered.samples,
                film,
            },
            elapsed: rendered.stats.elapsed.as_secs_f64(),
            paths: rendered.stats.counters.paths,
            notes: observer.notes.into_inner().expect("not poisoned"),
        })
    }
}

/// A grid's numpy shape: (z, y, x), with its channels last where it has several.
fn grid_shape(grid: &volpt::scene_files::GridDesc) -> Vec<usize> {
    let [x, y, z] = grid.resolution.map(|n| n as usize);
    let mut shape = vec![z, y, x];
    if grid.channels > 1 {
        shape.push(grid.channels as usize);
    }
    shape
}

/// `samples=`: a `range` of step 1, or `(start, stop)`.
fn sample_range(value: &Bound<'_, PyAny>) -> PyResult<Range<u32>> {
    let wrong = |why: &str| {
        settings_error(format!(
            "samples: expected a range(start, stop) with 0 <= start < stop <= 2^32 - 1{why}, \
             found {}",
            describe(value)
        ))
    };
    let (start, stop) = if let Ok(range) = value.downcast::<PyRange>() {
        if range.getattr("step")?.extract::<i64>()? != 1 {
            return Err(wrong(" and step 1"));
        }
        (range.getattr("start")?, range.getattr("stop")?)
    } else if let Ok((a, b)) = value.extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>() {
        (a, b)
    } else {
        return Err(wrong(""));
    };
    match (start.extract::<i64>(), stop.extract::<i64>()) {
        (Ok(a), Ok(b)) if 0 <= a && a < b && b <= i64::from(u32::MAX) => Ok(a as u32..b as u32),
        _ => Err(wrong("")),
    }
}

/// `backend=`, `strategy=`, `math=` as the library's options.
fn backend_options(
    backend: &str,
    strategy: Option<&str>,
    math: Option<&str>,
) -> PyResult<BackendOptions> {
    let kind = named::<BackendKind>(backend, "backend")?;
    let strategy = strategy
        .map(|name| named::<StrategyChoice>(name, "strategy"))
        .transpose()?;
    let math = math.map(|name| named::<Math>(name, "math")).transpose()?;
    Ok(BackendOptions {
        kind,
        gpu: GpuOptions {
            strategy,
            math,
            ..GpuOptions::default()
        },
    })
}

/// Backends opened so far, reused: a GPU's kernels compile once per process.
static BACKENDS: Mutex<Vec<(BackendOptions, Arc<Backend>)>> = Mutex::new(Vec::new());

fn open_backend(py: Python<'_>, options: &BackendOptions) -> PyResult<Arc<Backend>> {
    if let Some((_, backend)) = BACKENDS
        .lock()
        .expect("not poisoned")
        .iter()
        .find(|(o, _)| o == options)
    {
        return Ok(backend.clone());
    }
    let backend = Arc::new(py.allow_threads(|| Backend::open(options)).map_err(to_py)?);
    BACKENDS
        .lock()
        .expect("not poisoned")
        .push((*options, backend.clone()));
    Ok(backend)
}

/// A render's observer: counts progress, and between chunks (on the render's own thread) takes
/// the GIL to run signal handlers and the progress callback. An exception from either cancels the
/// render and is raised when it returns.
struct PyObserver {
    callback: Option<PyObject>,
    done: AtomicU64,
    total: AtomicU64,
    error: Mutex<Option<PyErr>>,
    notes: Mutex<Vec<String>>,
    every: Duration,
}

impl Observer for PyObserver {
    fn progress(&self, done: u64, total: u64) {
        self.done.fetch_max(done, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
    }

    fn note(&self, text: &str) {
        let text = text.trim_end().to_owned();
        if let Some(callback) = &self.callback {
            Python::with_gil(|py| {
                if let Ok(write) = callback.getattr(py, "note") {
                    let _ = write.call1(py, (text.as_str(),));
                }
            });
        }
        self.notes.lock().expect("not poisoned").push(text);
    }

    fn cancelled(&self) -> bool {
        Python::with_gil(|py| {
            let result = py.check_signals().and_then(|()| match &self.callback {
                Some(callback) => callback
                    .call1(
                        py,
                        (
                            self.done.load(Ordering::Relaxed),
                            self.total.load(Ordering::Relaxed),
                        ),
                    )
                    .map(drop),
                None => Ok(()),
            });
            match result {
                Ok(()) => false,
                Err(error) => {
                    *self.error.lock().expect("not poisoned") = Some(error);
                    true
                }
            }
        })
    }

    fn check_every(&self) -> Option<Duration> {
        Some(self.every)
    }
}

/// `scene.params`: the parameters that change between renders, as a mapping.
#[pyclass(module = "volpt._volpt", mapping)]
struct SceneParameters {
    scene: Py<Scene>,
}

impl SceneParameters {
    fn scene<'py>(&self, py: Python<'py>) -> PyResult<PyRef<'py, Scene>> {
        self.scene.bind(py).try_borrow().map_err(|_| {
            settings_error("scene.params: the scene is rendering in another thread".into())
        })
    }

    /// The keys this scene has, with what each is: every documented key it can get (not
    /// `medium.albedo` for an albedo grid), then its materials' (`volpt::Scene::params`).
    fn described(&self, py: Python<'_>) -> PyResult<Vec<(String, &'static str)>> {
        Ok(self.scene(py)?.inner.params())
    }

    /// The keys this scene has.
    fn present(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        Ok(self.described(py)?.into_iter().map(|(k, _)| k).collect())
    }
}

#[pymethods]
impl SceneParameters {
    fn __getitem__(&self, py: Python<'_>, key: &str) -> PyResult<PyObject> {
        get_param(py, &self.scene(py)?.inner, key)
    }

    fn __setitem__(&self, py: Python<'_>, key: &str, value: Bound<'_, PyAny>) -> PyResult<()> {
        // The key first, so that a wrong key says so whatever the value.
        if !self.present(py)?.iter().any(|k| k == key) {
            return Err(to_py(
                self.scene(py)?.inner.get(key).expect_err("unknown key"),
            ));
        }
        let value = param_from_py(key, &value)?;
        let mut scene = self.scene.bind(py).try_borrow_mut().map_err(|_| {
            settings_error("scene.params: the scene is rendering in another thread".into())
        })?;
        scene.inner.set(key, value).map_err(to_py)
    }

    fn __contains__(&self, py: Python<'_>, key: &str) -> PyResult<bool> {
        Ok(self.present(py)?.iter().any(|k| k == key))
    }

    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(self.present(py)?.len())
    }

    fn __iter__(&self, py: Python<'_>) -> PyResult<PyObject> {
        let keys = PyList::new(py, self.present(py)?)?;
        Ok(keys.try_iter()?.into_any().unbind())
    }

    fn keys<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, self.present(py)?)
    }

    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let scene = self.scene(py)?;
        let values = self
            .present(py)?
            .into_iter()
            .map(|k| get_param(py, &scene.inner, &k))
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, values)
    }

    fn items<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let scene = self.scene(py)?;
        let items = self
            .present(py)?
            .into_iter()
            .map(|k| {
                let value = get_param(py, &scene.inner, &k)?;
                Ok((k, value))
            })
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, items)
    }

    #[pyo3(signature = (key, default=None))]
    fn get(&self, py: Python<'_>, key: &str, default: Option<PyObject>) -> PyResult<PyObject> {
        match self.scene(py)?.inner.get(key) {
            Ok(value) => param_to_py(py, value),
            Err(_) => Ok(default.unwrap_or_else(|| py.None())),
        }
    }

    /// Sets several parameters at once: all of them, or (on the first refusal) none.
    #[pyo3(signature = (values=None, **kwargs))]
    fn update(
        &self,
        py: Python<'_>,
        values: Option<Bound<'_, PyAny>>,
        kwargs: Option<Bound<'_, PyDict>>,
    ) -> PyResult<()> {
        let mut pairs: Vec<(String, Bound<'_, PyAny>)> = Vec::new();
        if let Some(values) = values {
            let dict = PyDict::new(py);
            dict.call_method1("update", (values,))?;
            for (k, v) in dict.iter() {
                pairs.push((k.extract()?, v));
            }
        }
        if let Some(kwargs) = kwargs {
            for (k, v) in kwargs.iter() {
                pairs.push((k.extract()?, v));
            }
        }
        let mut scene = self.scene.bind(py).try_borrow_mut().map_err(|_| {
            settings_error("scene.params: the scene is rendering in another thread".into())
        })?;
        // Every value converted before any is set; then set in order, undone on a refusal.
        let mut converted = Vec::with_capacity(pairs.len());
        let present: Vec<String> = scene.inner.params().into_iter().map(|(k, _)| k).collect();
        for (key, value) in &pairs {
            if !present.contains(key) {
                return Err(to_py(scene.inner.get(key).expect_err("unknown key")));
            }
            converted.push((key.as_str(), param_from_py(key, value)?));
        }
        let mut undo = Vec::new();
        for (key, value) in converted {
            let before = scene.inner.get(key).ok();
            if let Err(error) = scene.inner.set(key, value) {
                for (key, before) in undo.into_iter().rev() {
                    let _ = scene.inner.set(key, before);
                }
                return Err(to_py(error));
            }
            if let Some(before) = before {
                undo.push((key, before));
            }
        }
        Ok(())
    }

    /// Each key this scene has, with what it is and what it takes.
    fn describe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (key, what) in self.described(py)? {
            dict.set_item(key, what)?;
        }
        Ok(dict)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let scene = self.scene(py)?;
        let items: Vec<String> = self
            .present(py)?
            .into_iter()
            .map(|k| match scene.inner.get(&k) {
                Ok(ParamValue::Int(v)) => format!("{k:?}: {v}"),
                Ok(ParamValue::Float(v)) => format!("{k:?}: {v}"),
                Ok(ParamValue::Rgb(v) | ParamValue::Vec3(v)) => {
                    format!("{k:?}: ({}, {}, {})", v[0], v[1], v[2])
                }
                Err(_) => format!("{k:?}: ?"),
            })
            .collect();
        Ok(format!("volpt.SceneParameters({{{}}})", items.join(", ")))
    }
}

// ---------------------------------------------------------------------------------------------
// Films

/// A film: the per-pixel sums of one render's samples `samples`, with what identifies the render.
#[pyclass(module = "volpt._volpt")]
#[derive(Clone)]
struct Film {
    part: Part,
    elapsed: f64,
    paths: u64,
    notes: Vec<String>,
}

impl Film {
    fn mean_image(&self) -> Image {
        self.part.film.image(self.part.samples.len() as u32)
    }
}

/// `values` (native-endian numbers, `width x height x 3`) as a writable numpy array of `dtype`.
fn to_numpy<'py>(
    py: Python<'py>,
    bytes: &[u8],
    dtype: &str,
    (width, height): (u32, u32),
) -> PyResult<Bound<'py, PyAny>> {
    let buffer = PyByteArray::new(py, bytes);
    py.import("numpy")?
        .call_method1("frombuffer", (buffer, dtype))?
        .call_method1("reshape", ((height as usize, width as usize, 3usize),))
}

fn f32_bytes(pixels: &[[f32; 3]]) -> Vec<u8> {
    pixels
        .iter()
        .flat_map(|p| p.iter().flat_map(|c| c.to_ne_bytes()))
        .collect()
}

#[pymethods]
impl Film {
    /// The image: each pixel's mean over the film's samples, rounded to float32, (H, W, 3).
    fn image<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let image = self.mean_image();
        to_numpy(
            py,
            &f32_bytes(&image.pixels),
            "float32",
            (image.width, image.height),
        )
    }

    /// The per-pixel sums of the film's samples, float64 (H, W, 3).
    #[getter]
    fn sums<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let film = &self.part.film;
        let bytes: Vec<u8> = film
            .sums
            .iter()
            .flat_map(|p| p.iter().flat_map(|c| c.to_ne_bytes()))
            .collect();
        to_numpy(py, &bytes, "float64", (film.width, film.height))
    }

    /// The samples of every pixel the film holds, as a `range`.
    #[getter]
    fn samples<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyRange>> {
        let s = &self.part.samples;
        PyRange::new(py, s.start as isize, s.end as isize)
    }

    #[getter]
    fn seed(&self) -> u32 {
        self.part.seed
    }

    #[getter]
    fn fingerprint(&self) -> u64 {
        self.part.fingerprint
    }

    #[getter]
    fn width(&self) -> u32 {
        self.part.film.width
    }

    #[getter]
    fn height(&self) -> u32 {
        self.part.film.height
    }

    /// Seconds the render took (0 for a loaded or merged film).
    #[getter]
    fn elapsed(&self) -> f64 {
        self.elapsed
    }

    /// Paths traced by the render (0 for a loaded film).
    #[getter]
    fn paths(&self) -> u64 {
        self.paths
    }

    /// What the render said (`auto`'s calibration and choice on a GPU).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.notes.clone()
    }

    /// Writes the image: OpenEXR (`.exr`, float32 linear) or PNG (`.png`, the CLI's preview).
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let image = self.mean_image();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        py.allow_threads(|| match ext.as_deref() {
            Some("exr") => image.write_exr(&path).map_err(Error::from),
            Some("png") => image.write_png(&path).map_err(Error::from),
            _ => Err(Error::Image(volpt::film::image::ImageError::Io {
                path: path.clone(),
                source: std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "expected a file name ending in .exr or .png",
                ),
            })),
        })
        .map_err(to_py)
    }

    /// Saves the film in volpt's checkpoint format (`volpt render --resume` continues it).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let part = &self.part;
        if part.samples.start != 0 {
            return Err(raise(
                "CheckpointError",
                format!(
                    "{}: a checkpoint holds samples 0..n of every pixel; this film holds samples \
                     {}..{} (merge it with the films of the samples before it first)",
                    path.display(),
                    part.samples.start,
                    part.samples.end
                ),
            ));
        }
        py.allow_threads(|| {
            Checkpoint::write_film(
                &path,
                part.fingerprint,
                part.seed,
                part.samples.end,
                &part.film,
            )
        })
        .map_err(|e| to_py(e.into()))
    }

    /// Reads a film saved by `Film.save` or `volpt render --checkpoint`; with `scene`, refuses a
    /// film of another scene (its fingerprint or size).
    #[staticmethod]
    #[pyo3(signature = (path, scene=None))]
    fn load(py: Python<'_>, path: PathBuf, scene: Option<PyRef<'_, Scene>>) -> PyResult<Film> {
        let header = read_header(&path);
        let (fingerprint, size, seed) = match (&scene, header) {
            (Some(scene), header) => (
                scene.inner.fingerprint(),
                scene.inner.resolution(),
                header.map_or(scene.inner.seed(), |h| h.2),
            ),
            (None, Some(header)) => header,
            // Unreadable or short: the reader says why.
            (None, None) => (0, (0, 0), 0),
        };
        let checkpoint = py
            .allow_threads(|| {
                let limit = volpt::scene_files::limits::memory_limit();
                Checkpoint::read(&path, fingerprint, size, seed, limit)
            })
            .map_err(|e| to_py(e.into()))?;
        Ok(Film {
            part: Part {
                fingerprint: checkpoint.fingerprint,
                seed: checkpoint.seed,
                samples: 0..checkpoint.samples,
                film: checkpoint.film,
            },
            elapsed: 0.0,
            paths: 0,
            notes: Vec::new(),
        })
    }

    /// Writes the film in the film file format (`VOLPTFL1`, what `volpt render --film` writes
    /// and `volpt merge` reads), atomically.
    fn save_film(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let part = &self.part;
        let file = volpt::FilmFile {
            fingerprint: part.fingerprint,
            seed: part.seed,
            ranges: vec![part.samples.clone()],
            film: part.film.clone(),
        };
        py.allow_threads(|| file.write(&path))
            .map_err(|e| to_py(e.into()))
    }

    /// Reads a film file (`volpt render --film`, `volpt merge --film`, `Film.save_film`) or a
    /// checkpoint; a film of several ranges (a merge with gaps) is refused.
    #[staticmethod]
    fn load_film(py: Python<'_>, path: PathBuf) -> PyResult<Film> {
        let file = py
            .allow_threads(|| volpt::read_film(&path))
            .map_err(to_py)?;
        let samples = match file.ranges.as_slice() {
            [range] => range.clone(),
            ranges => {
                return Err(raise(
                    "CheckpointError",
                    format!(
                        "{}: the film holds samples {}, not one range (merge it with the films \
                         of the samples between them first)",
                        path.display(),
                        volpt::film::film_file::format_ranges(ranges)
                    ),
                ))
            }
        };
        Ok(Film {
            part: Part {
                fingerprint: file.fingerprint,
                seed: file.seed,
                samples,
                film: file.film,
            },
            elapsed: 0.0,
            paths: 0,
            notes: Vec::new(),
        })
    }

    fn __repr__(&self) -> String {
        let p = &self.part;
        format!(
            "volpt.Film({}x{}, samples range({}, {}), seed {}, scene {:016x})",
            p.film.width, p.film.height, p.samples.start, p.samples.end, p.seed, p.fingerprint
        )
    }
}

/// A checkpoint's header (`volpt-film`'s format): fingerprint, film size and seed.
fn read_header(path: &Path) -> Option<(u64, (u32, u32), u32)> {
    use std::io::Read;
    let mut header = [0u8; 32];
    // A regular file only: opening a FIFO would block for ever.
    volpt::film::regular::open_regular(path)
        .ok()?
        .0
        .read_exact(&mut header)
        .ok()?;
    let u32_at = |i: usize| u32::from_le_bytes(header[i..i + 4].try_into().expect("4 bytes"));
    let fingerprint = u64::from_le_bytes(header[8..16].try_into().expect("8 bytes"));
    Some((fingerprint, (u32_at(16), u32_at(20)), u32_at(24)))
}

/// `volpt.merge`: the film of all the films' samples (see the stubs).
#[pyfunction]
fn merge(py: Python<'_>, films: Vec<PyRef<'_, Film>>) -> PyResult<Film> {
    let parts: Vec<Part> = films.iter().map(|f| f.part.clone()).collect();
    let part = py.allow_threads(|| volpt::merge(parts)).map_err(to_py)?;
    Ok(Film {
        part,
        elapsed: films.iter().map(|f| f.elapsed).sum(),
        paths: films.iter().map(|f| f.paths).sum(),
        notes: Vec::new(),
    })
}

/// `volpt.read_exr`: the first RGB layer of an OpenEXR file, float32 (H, W, 3).
#[pyfunction]
fn read_exr(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let image = py
        .allow_threads(|| {
            // What the header claims, against the memory limit, before the decoder allocates it
            // (as `volpt compare` does).
            volpt::scene_files::limits::check_exr(&path, "the image", 12)?;
            Ok::<_, volpt::Error>(Image::read_exr(&path)?)
        })
        .map_err(to_py)?;
    to_numpy(
        py,
        &f32_bytes(&image.pixels),
        "float32",
        (image.width, image.height),
    )
}

#[pymodule]
fn _volpt(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(read_exr, m)?)?;
    m.add_class::<Scene>()?;
    m.add_class::<SceneParameters>()?;
    m.add_class::<Film>()?;
    let params = PyDict::new(m.py());
    for (key, what) in PARAMS {
        params.set_item(key, what)?;
    }
    m.add("PARAMS", params)?;
    m.add("SETTINGS", PyTuple::new(m.py(), SETTINGS)?)?;
    m.add(
        "STRATEGIES",
        PyTuple::new(m.py(), volpt::names::names::<StrategyChoice>())?,
    )?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
