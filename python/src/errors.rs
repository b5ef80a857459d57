//! The exceptions: `volpt.errors`' classes (Python, for their several bases: `SettingsError` is
//! also a `ValueError`, `SceneNotFoundError` a `FileNotFoundError`), imported here by PyO3's
//! `import_exception!`; each library error raises the class of its variant, with the library's
//! message (file, field, expected, found) and each setting's key spelled as Python takes it.

use pyo3::prelude::*;
use volpt::Error;

pyo3::import_exception!(volpt.errors, SceneError);
pyo3::import_exception!(volpt.errors, SceneNotFoundError);
pyo3::import_exception!(volpt.errors, SettingsError);
pyo3::import_exception!(volpt.errors, ParamError);
pyo3::import_exception!(volpt.errors, UnknownParamError);
pyo3::import_exception!(volpt.errors, GridError);
pyo3::import_exception!(volpt.errors, RenderError);
pyo3::import_exception!(volpt.errors, CheckpointError);
pyo3::import_exception!(volpt.errors, MergeError);
pyo3::import_exception!(volpt.errors, ImageError);
pyo3::import_exception!(volpt.errors, PrintError);

/// The Python exception for `error`: the class of its variant, with its message.
pub fn to_py(error: Error) -> PyErr {
    let text = error.spelled(&python_spelling);
    let text = with_causes(&error, text);
    match &error {
        Error::Scene(volpt::SceneError::Io { error, .. })
            if error.kind() == std::io::ErrorKind::NotFound =>
        {
            SceneNotFoundError::new_err(text)
        }
        Error::Scene(_) => SceneError::new_err(text),
        Error::Setting { .. } | Error::Conflict { .. } | Error::FilmSize { .. } => {
            SettingsError::new_err(text)
        }
        Error::UnknownParam { .. } => UnknownParamError::new_err(text),
        Error::Param { .. } => ParamError::new_err(text),
        Error::Grid { .. } => GridError::new_err(text),
        Error::Cpu(_) | Error::Cuda(_) => RenderError::new_err(text),
        Error::Checkpoint(_) | Error::FilmFile(_) => CheckpointError::new_err(text),
        Error::Films(_) => MergeError::new_err(text),
        Error::Image(_) => ImageError::new_err(text),
    }
}

/// A setting as Python takes it: a key of `volpt.load`'s settings mapping
/// (`settings["max_depth"]`), else a keyword argument (`strategy`), with its value where it has
/// one (`strategy='naive-sk'`).
fn python_spelling(key: &str, value: Option<&str>) -> String {
    let setting = crate::convert::SETTINGS.contains(&key);
    let key = if setting {
        format!("settings[{key:?}]")
    } else {
        key.to_owned()
    };
    let Some(value) = value else {
        return key;
    };
    // Python's literals: numbers and booleans bare, names quoted.
    let value = match value {
        "true" => "True".to_owned(),
        "false" => "False".to_owned(),
        v if v.parse::<f64>().is_ok() => v.to_owned(),
        v => format!("'{v}'"),
    };
    if setting {
        format!("{key} = {value}")
    } else {
        format!("{key}={value}")
    }
}

/// `text` with the causes of `error` that it does not already say.
fn with_causes(error: &dyn std::error::Error, mut text: String) -> String {
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
