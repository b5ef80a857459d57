//! `volpt.Film`: the per-pixel sums of one render's samples with what identifies the render (a
//! [`volpt::Part`]); its images, its files (checkpoints, film files) and its bytes, which pickle
//! it (Ray passes films between processes so); `volpt.merge` and `volpt.read_exr`.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyRange, PyType};
use volpt::{Error, Image, Part};

use crate::convert::{f32_bytes, f64_bytes, image_shape, to_numpy};
use crate::errors::to_py;
use crate::scene::Scene;

/// A film: the per-pixel sums of one render's samples `samples`, with what identifies the render.
#[pyclass(module = "volpt._volpt")]
#[derive(Clone)]
pub struct Film {
    pub part: Part,
    pub elapsed: f64,
    pub paths: u64,
    pub notes: Vec<String>,
}

impl Film {
    /// A film of `part` that no render here made (loaded, merged, unpickled).
    fn of(part: Part) -> Self {
        Film {
            part,
            elapsed: 0.0,
            paths: 0,
            notes: Vec::new(),
        }
    }

    fn mean_image(&self) -> Image {
        self.part.film.image(self.part.samples.len() as u32)
    }
}

#[pymethods]
impl Film {
    /// The image: each pixel's mean over the film's samples, rounded to float32, (H, W, 3).
    fn image<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let image = self.mean_image();
        let shape = image_shape((image.width, image.height));
        to_numpy(py, &f32_bytes(&image.pixels), "float32", shape)
    }

    /// The per-pixel sums of the film's samples, float64 (H, W, 3).
    #[getter]
    fn sums<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let film = &self.part.film;
        let shape = image_shape((film.width, film.height));
        to_numpy(py, &f64_bytes(&film.sums), "float64", shape)
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
        py.allow_threads(|| image.write(&path).map_err(Error::from))
            .map_err(to_py)
    }

    /// Saves the film in volpt's checkpoint format (`volpt render --resume` continues it).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let part = &self.part;
        py.allow_threads(|| part.save_checkpoint(&path))
            .map_err(to_py)
    }

    /// Reads a film saved by `Film.save` or `volpt render --checkpoint`; with `scene`, refuses a
    /// film of another scene (its fingerprint or size).
    #[staticmethod]
    #[pyo3(signature = (path, scene=None))]
    fn load(py: Python<'_>, path: PathBuf, scene: Option<PyRef<'_, Scene>>) -> PyResult<Film> {
        let scene = scene.as_deref().map(|s| &s.inner);
        let part = py
            .allow_threads(|| Part::read_checkpoint(&path, scene))
            .map_err(to_py)?;
        Ok(Film::of(part))
    }

    /// Writes the film in the film file format (`VOLPTFL1`, what `volpt render --film` writes
    /// and `volpt merge` reads), atomically.
    fn save_film(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let part = &self.part;
        py.allow_threads(|| part.write_film(&path)).map_err(to_py)
    }

    /// Reads a film file (`volpt render --film`, `volpt merge --film`, `Film.save_film`) or a
    /// checkpoint; a film of several ranges (a merge with gaps) is refused.
    #[staticmethod]
    fn load_film(py: Python<'_>, path: PathBuf) -> PyResult<Film> {
        let part = py.allow_threads(|| Part::read_film(&path)).map_err(to_py)?;
        Ok(Film::of(part))
    }

    /// The film as the film file's bytes (what `save_film` writes).
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let part = &self.part;
        let bytes = py.allow_threads(|| part.to_bytes()).map_err(to_py)?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// The film of `to_bytes`' bytes, checked as a film file is (magic, length, checksum).
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Film> {
        let part = py.allow_threads(|| Part::from_bytes(data)).map_err(to_py)?;
        Ok(Film::of(part))
    }

    /// Pickling: the film file's bytes, read back by `Film.from_bytes`. What identifies the
    /// render travels; the render's time, path count and notes do not.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let py = slf.py();
        let from_bytes = PyType::new::<Film>(py).getattr("from_bytes")?;
        Ok((from_bytes, (slf.borrow().to_bytes(py)?,)))
    }

    fn __repr__(&self) -> String {
        let p = &self.part;
        format!(
            "volpt.Film({}x{}, samples range({}, {}), seed {}, scene {:016x})",
            p.film.width, p.film.height, p.samples.start, p.samples.end, p.seed, p.fingerprint
        )
    }
}

/// `volpt.merge`: the film of all the films' samples (see the stubs).
#[pyfunction]
pub fn merge(py: Python<'_>, films: Vec<PyRef<'_, Film>>) -> PyResult<Film> {
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
pub fn read_exr(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let image = py
        .allow_threads(|| volpt::read_exr(&path, "the image"))
        .map_err(to_py)?;
    let shape = image_shape((image.width, image.height));
    to_numpy(py, &f32_bytes(&image.pixels), "float32", shape)
}
