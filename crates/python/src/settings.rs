//! Keyword arguments named like the CLI's flags (`spp=16`, `accel="bvh"`, `threads=4`):
//! the keys, ranges and names of the render crate's one settings table
//! ([`raylab_render::settings::SETTINGS`]), so that a bad value gives the same message as
//! `raylab render --spp 0` or a scene file would.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use raylab_loader::Overrides;
use raylab_render::settings::{SettingKind, SettingValue, SETTINGS};

/// Worker threads: a keyword beside the settings, not a scene setting.
const THREADS: &str = "threads";

/// Every keyword `render`, `Scene` and `Scene.set` accept: the settings table's, and `threads`.
pub fn names() -> Vec<&'static str> {
    SETTINGS.iter().map(|s| s.key).chain([THREADS]).collect()
}

/// Scene overrides plus the size of the thread pool, which is not a scene setting.
#[derive(Clone, Debug, Default)]
pub struct Settings {
    pub overrides: Overrides,
    pub threads: Option<u32>,
}

/// An integer keyword in `lo..=hi` (the CLI's clap ranges); bools are refused although
/// Python counts them as integers.
fn int_in(name: &str, v: &Bound<'_, PyAny>, lo: u64, hi: u64) -> PyResult<u64> {
    let n = if v.is_instance_of::<pyo3::types::PyBool>() { None } else { v.extract::<i128>().ok() };
    match n {
        Some(n) if n >= lo as i128 && n <= hi as i128 => Ok(n as u64),
        _ => Err(PyValueError::new_err(format!("{name}: expected an integer from {lo} to {hi}, found {}", v.repr()?))),
    }
}

/// A name keyword: a string, or a `TypeError`.
fn name_in(name: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
    v.extract().map_err(|_| PyTypeError::new_err(format!("{name}: expected a string, found {}", v.get_type().name().map(|n| n.to_string()).unwrap_or_default())))
}

/// Parses `kwargs`; `caller` names the function in the error for an unknown keyword.
pub fn parse(caller: &str, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Settings> {
    let mut s = Settings::default();
    let Some(kwargs) = kwargs else { return Ok(s) };
    for (k, v) in kwargs.iter() {
        let key: String = k.extract()?;
        if v.is_none() {
            // `spp=None` means "the scene's", as when the flag is left out.
            continue;
        }
        if key == THREADS {
            s.threads = Some(int_in(THREADS, &v, 1, 1024)? as u32);
            continue;
        }
        let Some(spec) = SETTINGS.iter().find(|s| s.key == key) else {
            return Err(PyTypeError::new_err(format!("{caller}() got an unexpected keyword argument '{key}' (valid: {})", names().join(", "))));
        };
        let set = match spec.kind {
            SettingKind::Integer { min, max } => s.overrides.set(spec.key, SettingValue::Integer(int_in(spec.key, &v, min, max)? as i128)),
            SettingKind::Name(_) => s.overrides.set(spec.key, SettingValue::Name(&name_in(spec.key, &v)?)),
        };
        set.map_err(|e| PyValueError::new_err(format!("{key}: {e}")))?;
    }
    Ok(s)
}

/// `later` on top of `earlier`: the values `later` sets win.
pub fn merge(earlier: &Overrides, later: &Overrides) -> Overrides {
    later.or(earlier)
}

/// A thread pool of the requested size, or `None` for rayon's global pool (all cores).
pub fn pool(threads: Option<u32>) -> PyResult<Option<rayon::ThreadPool>> {
    threads
        .map(|n| rayon::ThreadPoolBuilder::new().num_threads(n as usize).build().map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("cannot start {n} threads: {e}"))))
        .transpose()
}

/// Runs `f` in `pool` when there is one.
pub fn install<T: Send>(pool: Option<&rayon::ThreadPool>, f: impl FnOnce() -> T + Send) -> T {
    match pool {
        Some(p) => p.install(f),
        None => f(),
    }
}
