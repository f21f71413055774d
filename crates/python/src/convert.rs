//! Plain Python data from raylab's serialisable reports (the JSON schema's dicts), and
//! NumPy arrays from images.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use pyo3::IntoPyObjectExt;
use raylab_core::Rgb;
use serde_json::Value;

/// A JSON value as Python objects: dicts, lists, ints, floats, strings, None.
pub fn json_to_py(py: Python<'_>, v: &Value) -> PyResult<Py<PyAny>> {
    Ok(match v {
        Value::Null => py.None(),
        Value::Bool(b) => b.into_py_any(py)?,
        Value::Number(n) => match (n.as_u64(), n.as_i64()) {
            (Some(u), _) => u.into_py_any(py)?,
            (None, Some(i)) => i.into_py_any(py)?,
            _ => n.as_f64().unwrap_or(f64::NAN).into_py_any(py)?,
        },
        Value::String(s) => s.into_py_any(py)?,
        Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(json_to_py(py, x)?)?;
            }
            list.into_any().unbind()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, json_to_py(py, x)?)?;
            }
            d.into_any().unbind()
        }
    })
}

/// Any serialisable value as plain Python data.
pub fn to_py<T: serde::Serialize>(py: Python<'_>, v: &T) -> PyResult<Py<PyAny>> {
    let json = serde_json::to_value(v).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("cannot convert a report: {e}")))?;
    json_to_py(py, &json)
}

/// One value per pixel as an `(H, W)` float32 array, non-finite values as 0.
pub fn scalar_array<'py>(py: Python<'py>, width: u32, height: u32, values: &[f32]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = values.iter().map(|&v| if v.is_finite() { v } else { 0.0 }).collect();
    Ok(PyArray1::from_vec(py, flat).reshape([height as usize, width as usize])?.into_any())
}

/// An image as an `(H, W, 3)` float32 array, row 0 at the top, with the values the PFM
/// writer stores (non-finite values become 0, as there).
pub fn image_array<'py>(py: Python<'py>, width: u32, height: u32, pixels: &[Rgb]) -> PyResult<Bound<'py, PyAny>> {
    let finite = |v: f32| if v.is_finite() { v } else { 0.0 };
    let flat: Vec<f32> = pixels.iter().flat_map(|p| [finite(p.x), finite(p.y), finite(p.z)]).collect();
    Ok(PyArray1::from_vec(py, flat).reshape([height as usize, width as usize, 3])?.into_any())
}
