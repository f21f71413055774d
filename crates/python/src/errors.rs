//! raylab's errors as Python exceptions. A scene that cannot be loaded raises
//! `raylab.RaylabError` (a `ValueError`) whose message is raylab's own
//! `file:line: field: message`, with `file`, `line` and `field` also set as attributes.

use pyo3::prelude::*;
use pyo3::{create_exception, exceptions::PyValueError};
use raylab_loader::LoadError;

create_exception!(raylab, RaylabError, PyValueError, "An error raylab reports about its input: a scene, mesh, image or ray file, or a structure that fails validation. The message names the file, line and field.");

/// Converts a loader error, keeping its parts as attributes.
pub fn load_error(e: LoadError) -> PyErr {
    let err = RaylabError::new_err(e.to_string());
    Python::attach(|py| {
        let v = err.value(py);
        // Setting attributes on a fresh exception instance cannot fail in practice; if it
        // did, the message alone still carries everything.
        let _ = v.setattr("file", e.file.display().to_string());
        let _ = v.setattr("line", e.line);
        let _ = v.setattr("field", if e.field.is_empty() { None } else { Some(e.field.clone()) });
    });
    err
}

/// Any other error of raylab's with a `Display` message.
pub fn raylab_error(e: impl std::fmt::Display) -> PyErr {
    RaylabError::new_err(e.to_string())
}
