//! `scene.params`: the parameters that change between renders, as a mapping (Mitsuba's
//! `mi.traverse`), over the library's [`volpt::Scene::get`] and [`volpt::Scene::set`].

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use volpt::{ParamValue, PARAMS};

use crate::convert::describe;
use crate::errors::{to_py, ParamError, SettingsError};
use crate::scene::Scene;

/// `scene.params`: the parameters that change between renders, as a mapping.
#[pyclass(module = "volpt._volpt", mapping)]
pub struct SceneParameters {
    pub scene: Py<Scene>,
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
        ParamError::new_err(format!(
            "parameter {key}: expected {expected}, found {}",
            describe(value)
        ))
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

fn busy() -> PyErr {
    SettingsError::new_err("scene.params: the scene is rendering in another thread")
}

impl SceneParameters {
    fn scene<'py>(&self, py: Python<'py>) -> PyResult<PyRef<'py, Scene>> {
        self.scene.bind(py).try_borrow().map_err(|_| busy())
    }

    fn scene_mut<'py>(&self, py: Python<'py>) -> PyResult<PyRefMut<'py, Scene>> {
        self.scene.bind(py).try_borrow_mut().map_err(|_| busy())
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

/// `UnknownParamError` for `key` unless it is a parameter's (a material-indexed volume's
/// materials' included).
fn known(scene: &volpt::Scene, key: &str) -> PyResult<()> {
    if PARAMS.iter().any(|(k, _)| *k == key) || scene.params().iter().any(|(k, _)| k == key) {
        return Ok(());
    }
    Err(to_py(scene.get(key).expect_err("unknown key")))
}

#[pymethods]
impl SceneParameters {
    fn __getitem__(&self, py: Python<'_>, key: &str) -> PyResult<PyObject> {
        get_param(py, &self.scene(py)?.inner, key)
    }

    fn __setitem__(&self, py: Python<'_>, key: &str, value: Bound<'_, PyAny>) -> PyResult<()> {
        // The key first, so that a wrong key says so whatever the value.
        known(&self.scene(py)?.inner, key)?;
        let value = param_from_py(key, &value)?;
        self.scene_mut(py)?.inner.set(key, value).map_err(to_py)
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
        let mut scene = self.scene_mut(py)?;
        // Every value converted before any is set; then set in order, undone on a refusal.
        let mut converted = Vec::with_capacity(pairs.len());
        for (key, value) in &pairs {
            known(&scene.inner, key)?;
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
