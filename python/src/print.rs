//! `volpt.compensate_print`: the scattering compensation of a colour 3D print, as `volpt print
//! compensate` runs it (volpt-print's `job::run`, the same record from the same arguments), the
//! GIL released; progress and Ctrl-C through [`PyObserver`]: Ctrl-C writes the record of the
//! iterations finished and then raises `KeyboardInterrupt`.

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use volpt::BackendKind;
use volpt_print::compensate::{CompensateError, Iteration, Options, Update};
use volpt_print::job::{run_on, Job, JobError, Renderer};
use volpt_print::predict::PredictError;

use crate::backend::Backend;
use crate::convert::describe;
use crate::errors::{to_py, PrintError, SettingsError};
use crate::film::Film;
use crate::observer::PyObserver;
use crate::scene::{choose, Chosen};

/// The Python exception for a compensation's error: a render's as any render's, a bad argument
/// or file as `PrintError` (a `ValueError`).
fn job_error(error: JobError) -> PyErr {
    match error {
        JobError::Compensate(e) => match *e {
            CompensateError::Predictor(PredictError::Volpt(e)) => to_py(e),
            other => print_error(&other),
        },
        other => print_error(&other),
    }
}

/// `PrintError` with the error's message and its causes' (those it does not already say).
fn print_error(error: &dyn std::error::Error) -> PyErr {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        let cause_text = cause.to_string();
        if !text.contains(&cause_text) {
            text.push_str(": ");
            text.push_str(&cause_text);
        }
        source = cause.source();
    }
    PrintError::new_err(text)
}

/// The image of a `render=` callable's film: samples `0..samples` of the print's scene.
fn film_image(py: Python<'_>, film: PyObject, samples: u32) -> PyResult<volpt::Image> {
    let film = film.bind(py);
    let Ok(film) = film.downcast::<Film>() else {
        return Err(SettingsError::new_err(format!(
            "render: expected it to return a volpt.Film, found {}",
            describe(film)
        )));
    };
    let part = &film.borrow().part;
    if part.samples != (0..samples) {
        return Err(SettingsError::new_err(format!(
            "render: expected a film of samples 0..{samples}, found {:?}",
            part.samples
        )));
    }
    Ok(part.film.image(samples))
}

/// An iteration as Python sees it: `{"mean", "p95", "noise", "spp"}`.
fn summary<'py>(py: Python<'py>, it: &Iteration) -> PyResult<Bound<'py, PyDict>> {
    let row = PyDict::new(py);
    row.set_item("mean", it.mean)?;
    row.set_item("p95", it.p95)?;
    row.set_item("noise", it.noise)?;
    row.set_item("spp", it.samples)?;
    Ok(row)
}

/// See the stubs (`python/volpt/_volpt.pyi`) for the Python documentation.
#[pyfunction]
#[pyo3(signature = (target, materials, out, *, layers=100, colour_layers=40, voxel_size=None,
                    spp=16, max_spp=volpt_print::predict::RenderPredictor::MAX_SPP,
                    iterations=None, step=None, noise_ratio=Some(0.25), update="cross-talk",
                    ior=Some(1.5), seed=0,
                    backend=None, render=None, progress=None, iteration=None))]
#[allow(clippy::too_many_arguments)]
pub fn compensate_print<'py>(
    py: Python<'py>,
    target: PathBuf,
    materials: PathBuf,
    out: PathBuf,
    layers: u32,
    colour_layers: u32,
    voxel_size: Option<[f64; 3]>,
    spp: u32,
    max_spp: u32,
    iterations: Option<usize>,
    step: Option<f64>,
    noise_ratio: Option<f64>,
    update: &str,
    ior: Option<f32>,
    seed: u32,
    backend: Option<Bound<'py, PyAny>>,
    render: Option<Bound<'py, PyAny>>,
    progress: Option<Bound<'py, PyAny>>,
    iteration: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    if let Some(callback) = iteration.as_ref().filter(|c| !c.is_callable()) {
        return Err(SettingsError::new_err(format!(
            "iteration: expected a callable(k, iteration), found {}",
            describe(callback)
        )));
    }
    if let Some(callback) = render.as_ref().filter(|c| !c.is_callable()) {
        return Err(SettingsError::new_err(format!(
            "render: expected a callable(scene_path, samples, seed) returning a volpt.Film, found {}",
            describe(callback)
        )));
    }
    if render.is_some() && backend.is_some() {
        return Err(SettingsError::new_err(
            "render and backend: expected one of them (render renders every prediction itself)",
        ));
    }
    let update = match update {
        "cross-talk" => Update::CrossTalk,
        "per-texel" => Update::PerTexel,
        _ => {
            return Err(SettingsError::new_err(format!(
                "update: expected \"cross-talk\" or \"per-texel\", found {update:?}"
            )))
        }
    };
    let iteration = iteration.map(Bound::unbind);
    let render = render.map(Bound::unbind);
    // No backend named: a GPU where one is usable, else the CPU (volpt::Backend::open_preferred).
    let (backend, reason) = match (&backend, &render) {
        (Some(backend), _) => (Some(choose(backend, None, None)?), "backend=".to_owned()),
        (None, Some(_)) => (None, "render=".to_owned()),
        (None, None) => {
            let (backend, reason) = Backend::preferred(py)?;
            (Some(Chosen::Opened(Box::new(backend))), reason)
        }
    };
    let defaults = Options::default();
    let mut job = Job::new(target, materials, out);
    job.layers = layers;
    job.colour_layers = colour_layers;
    job.voxel_size = voxel_size;
    job.spp = spp;
    job.max_spp = max_spp;
    job.seed = seed;
    job.ior = ior;
    job.options = Options {
        max_iterations: iterations.unwrap_or(defaults.max_iterations),
        step: step.unwrap_or(defaults.step),
        noise_ratio,
        update,
        ..defaults
    };
    let kind = backend
        .as_ref()
        .map_or(BackendKind::Cpu, |b| b.inner.kind());
    let device = match &backend {
        Some(b) => b.inner.device_name(),
        None => "render=".to_owned(),
    };
    let observer = Arc::new(PyObserver::new(progress, kind)?);
    let shared = observer.clone();
    let observer = &observer;
    let renderer = match (&backend, &render) {
        (Some(b), _) => Renderer::Backend(&b.inner),
        (None, Some(render)) => Renderer::Elsewhere(Box::new(move |scene, samples, seed| {
            Python::with_gil(|py| {
                let film = render
                    .call1(py, (scene.to_path_buf(), samples, seed))
                    .and_then(|film| film_image(py, film, samples));
                // Its exception (a render that failed, Ctrl-C) stops the loop as Ctrl-C does,
                // and is raised after the record of the iterations finished is written.
                film.map_err(|error| observer.fail(error)).ok()
            })
        })),
        (None, None) => unreachable!("a backend is opened where no render is given"),
    };
    let outcome = py.allow_threads(|| {
        run_on(&job, renderer, shared, |k, it| {
            if let Some(callback) = &iteration {
                Python::with_gil(|py| {
                    // Its exception (Ctrl-C's KeyboardInterrupt, while it runs) stops the loop
                    // as Ctrl-C does, and is raised after the record is written.
                    let called = summary(py, it).and_then(|row| callback.call1(py, (k, row)));
                    if let Err(error) = called {
                        observer.fail(error);
                    }
                });
            }
        })
    });
    // Ctrl-C (or the progress callback's exception) stopped the loop: its record is written;
    // the exception is raised now.
    if let Some(error) = observer.take_error() {
        return Err(error);
    }
    let outcome = outcome.map_err(job_error)?;
    observer.done(py)?;
    let c = &outcome.compensation;
    let iterations = PyList::empty(py);
    for it in &c.iterations {
        iterations.append(summary(py, it)?)?;
    }
    let result = PyDict::new(py);
    result.set_item("iterations", iterations)?;
    result.set_item("best", c.best)?;
    result.set_item("size", (outcome.size[0], outcome.size[1]))?;
    result.set_item("seconds", outcome.seconds)?;
    result.set_item("out", job.out.clone())?;
    result.set_item("backend", device)?;
    result.set_item("backend_reason", reason)?;
    Ok(result)
}
