//! Keyword arguments named like the CLI's flags (`spp=16`, `accel="bvh"`, `threads=4`),
//! checked with the CLI's ranges and parsed with the library's own name parsers, so that a
//! bad value gives the same message as `raylab render --spp 0` would.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use raylab_accel::AccelKind;
use raylab_loader::Overrides;
use raylab_render::filter::PixelFilter;
use raylab_render::integrator::MisHeuristic;
use raylab_render::light::LightSampling;
use raylab_render::{IntegratorKind, SamplerKind};

/// Every keyword `render`, `Scene` and `Scene.set` accept.
pub const NAMES: &[&str] = &["spp", "width", "height", "max_depth", "sampler", "integrator", "light_sampling", "light_cells", "mis_heuristic", "accel", "seed", "filter", "threads"];

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

fn name_of<T: std::str::FromStr>(name: &str, v: &Bound<'_, PyAny>) -> PyResult<T>
where
    T::Err: std::fmt::Display,
{
    let s: String = v.extract().map_err(|_| PyTypeError::new_err(format!("{name}: expected a string, found {}", v.get_type().name().map(|n| n.to_string()).unwrap_or_default())))?;
    s.parse::<T>().map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
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
        let o = &mut s.overrides;
        match key.as_str() {
            "spp" => o.spp = Some(int_in("spp", &v, 1, 1 << 20)? as u32),
            "width" => o.width = Some(int_in("width", &v, 1, 16384)? as u32),
            "height" => o.height = Some(int_in("height", &v, 1, 16384)? as u32),
            "max_depth" => o.max_depth = Some(int_in("max_depth", &v, 1, 1024)? as u32),
            "light_cells" => o.light_cells = Some(int_in("light_cells", &v, 1, 16)? as u32),
            "seed" => o.seed = Some(int_in("seed", &v, 0, u64::MAX)?),
            "threads" => s.threads = Some(int_in("threads", &v, 1, 1024)? as u32),
            "sampler" => o.sampler = Some(name_of::<SamplerKind>("sampler", &v)?),
            "integrator" => o.integrator = Some(name_of::<IntegratorKind>("integrator", &v)?),
            "light_sampling" => o.light_sampling = Some(name_of::<LightSampling>("light_sampling", &v)?),
            "mis_heuristic" => o.mis_heuristic = Some(name_of::<MisHeuristic>("mis_heuristic", &v)?),
            "accel" => o.accel = Some(name_of::<AccelKind>("accel", &v)?),
            "filter" => o.filter = Some(name_of::<PixelFilter>("filter", &v)?),
            _ => return Err(PyTypeError::new_err(format!("{caller}() got an unexpected keyword argument '{key}' (valid: {})", NAMES.join(", ")))),
        }
    }
    Ok(s)
}

/// `later` on top of `earlier`: the values `later` sets win.
pub fn merge(earlier: &Overrides, later: &Overrides) -> Overrides {
    Overrides {
        width: later.width.or(earlier.width),
        height: later.height.or(earlier.height),
        spp: later.spp.or(earlier.spp),
        max_depth: later.max_depth.or(earlier.max_depth),
        sampler: later.sampler.or(earlier.sampler),
        integrator: later.integrator.or(earlier.integrator),
        light_sampling: later.light_sampling.or(earlier.light_sampling),
        light_cells: later.light_cells.or(earlier.light_cells),
        mis_heuristic: later.mis_heuristic.or(earlier.mis_heuristic),
        accel: later.accel.or(earlier.accel),
        seed: later.seed.or(earlier.seed),
        filter: later.filter.or(earlier.filter),
        build: later.build.clone().or_else(|| earlier.build.clone()),
        lenient: later.lenient || earlier.lenient,
    }
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
