//! A render's [`Observer`] in Python: progress counted as it comes, and between chunks of samples
//! (on the render's own thread) the GIL taken back briefly to run Python's signal handlers
//! (Ctrl-C raises `KeyboardInterrupt` there) and the progress callback. The worker threads never
//! touch Python, so a render cannot deadlock against the interpreter.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::Duration;

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use volpt::{BackendKind, Observer};

use crate::convert::describe;

/// How much CPU rendering passes between looks at Ctrl-C and the progress callback.
const CPU_CHECK_EVERY: Duration = Duration::from_millis(100);
/// The same on a GPU: each chunk is a launch with its tail, so chunks are longer there.
const CUDA_CHECK_EVERY: Duration = Duration::from_millis(500);

/// An exception from the callback or a signal handler cancels the render and is raised when it
/// returns ([`PyObserver::take_error`]).
pub struct PyObserver {
    callback: Option<PyObject>,
    done: AtomicU64,
    total: AtomicU64,
    error: Mutex<Option<PyErr>>,
    notes: Mutex<Vec<String>>,
    every: Duration,
}

impl PyObserver {
    /// `progress=`: `True` (a bar on stderr), a callable `progress(done, total)`, or none; looks
    /// every [`CPU_CHECK_EVERY`] or [`CUDA_CHECK_EVERY`] as the backend is `kind`.
    pub fn new(progress: Option<Bound<'_, PyAny>>, kind: BackendKind) -> PyResult<Self> {
        let callback = match progress {
            None => None,
            Some(p) if p.is_instance_of::<pyo3::types::PyBool>() => {
                if p.extract::<bool>()? {
                    let py = p.py();
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
        Ok(Self {
            callback,
            done: AtomicU64::new(0),
            total: AtomicU64::new(0),
            error: Mutex::new(None),
            notes: Mutex::new(Vec::new()),
            every: match kind {
                BackendKind::Cpu => CPU_CHECK_EVERY,
                BackendKind::Cuda => CUDA_CHECK_EVERY,
            },
        })
    }

    /// Keeps `error` to raise after the render, and cancels it: the next look at
    /// [`Observer::cancelled`] stops it.
    pub fn fail(&self, error: PyErr) {
        self.error
            .lock()
            .expect("not poisoned")
            .get_or_insert(error);
    }

    /// After the render: the exception that cancelled it, if one did.
    pub fn take_error(&self) -> Option<PyErr> {
        self.error.lock().expect("not poisoned").take()
    }

    /// What the render said (`auto`'s calibration and choice on a GPU).
    pub fn into_notes(self) -> Vec<String> {
        self.notes.into_inner().expect("not poisoned")
    }

    /// The callback called with the whole done, after a render that succeeded.
    pub fn done(&self, py: Python<'_>) -> PyResult<()> {
        if let Some(callback) = &self.callback {
            let total = self.total.load(Ordering::Relaxed).max(1);
            callback.call1(py, (total, total))?;
        }
        Ok(())
    }
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
        if self.error.lock().expect("not poisoned").is_some() {
            return true;
        }
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
