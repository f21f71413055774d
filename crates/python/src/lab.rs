//! The lab from Python: bench, compare and converge, returning the plain dicts of the JSON
//! schema (docs/bench.md) ready for pandas. The method is the lab's (`raylab_lab::sweep`), the
//! one `raylab bench` runs: ray sets generated once per scene, builds and traces repeated with
//! a warm-up, medians, every structure checked against an oracle.

use std::path::PathBuf;

use numpy::{PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use raylab_accel::AccelKind;
use raylab_core::Rgb;
use raylab_lab::bench::BenchReport;
use raylab_lab::sweep::{self, BenchSettings, LabError, Progress};
use raylab_lab::compare::{compare as compare_images, ImageDiff};
use raylab_lab::converge::{measure, render_with, spp_slope, strategies as strategy_names, Study, REFERENCE_SEED_XOR};
use raylab_lab::RayKind;
use raylab_loader::image_io::read_image;
use raylab_loader::Overrides;
use raylab_render::light::LightSampling;
use raylab_render::IntegratorKind;

use crate::convert::{image_array, to_py};
use crate::errors::{load_error, raylab_error, RaylabError};
use crate::interrupt;
use crate::settings;

fn names<T: std::str::FromStr>(what: &str, list: &[String]) -> PyResult<Vec<T>>
where
    T::Err: std::fmt::Display,
{
    list.iter().map(|s| s.trim().parse::<T>().map_err(|e| PyValueError::new_err(format!("{what}: {e}")))).collect()
}

/// A list argument given as one comma-separated string or a sequence of strings.
fn string_list(v: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    if let Ok(s) = v.extract::<String>() {
        return Ok(s.split(',').map(|x| x.trim().to_string()).collect());
    }
    v.extract()
}

/// Errors of a job on another thread, turned into exceptions on the caller's.
enum JobError {
    Load(raylab_loader::LoadError),
    Other(String),
}

impl From<JobError> for PyErr {
    fn from(e: JobError) -> Self {
        match e {
            JobError::Load(e) => load_error(e),
            JobError::Other(m) => RaylabError::new_err(m),
        }
    }
}

impl From<LabError> for JobError {
    fn from(e: LabError) -> Self {
        match e {
            LabError::Load(e) => JobError::Load(e),
            e => JobError::Other(e.to_string()),
        }
    }
}

/// The sweep's progress from Python: only Ctrl-C matters.
struct CancelOnInterrupt(interrupt::Cancel);

impl Progress for CancelOnInterrupt {
    fn cancelled(&self) -> bool {
        self.0.is_set()
    }
}

/// `raylab.bench`: every structure on the same rays; the `raylab bench --json` dict.
#[pyfunction]
#[pyo3(signature = (scenes=None, *, accels=None, rays=None, resolution=256, repeats=3, threads=None, oracle_limit=20000, seed=1))]
#[allow(clippy::too_many_arguments)]
pub fn bench(
    py: Python<'_>,
    scenes: Option<&Bound<'_, PyAny>>,
    accels: Option<&Bound<'_, PyAny>>,
    rays: Option<&Bound<'_, PyAny>>,
    resolution: u32,
    repeats: u32,
    threads: Option<u32>,
    oracle_limit: usize,
    seed: u64,
) -> PyResult<Py<PyAny>> {
    if !(1..=8192).contains(&resolution) {
        return Err(PyValueError::new_err(format!("resolution: expected an integer from 1 to 8192, found {resolution}")));
    }
    if !(1..=1000).contains(&repeats) {
        return Err(PyValueError::new_err(format!("repeats: expected an integer from 1 to 1000, found {repeats}")));
    }
    let scenes: Vec<Option<PathBuf>> = match scenes {
        None => vec![None],
        Some(s) => match s.extract::<PathBuf>() {
            Ok(p) => vec![Some(p)],
            Err(_) => s.extract::<Vec<PathBuf>>()?.into_iter().map(Some).collect(),
        },
    };
    let accel_names = accels.map(string_list).transpose()?.unwrap_or_else(|| vec!["all".into()]);
    let all = accel_names == ["all"];
    let accels = if all { AccelKind::ALL.to_vec() } else { names::<AccelKind>("accels", &accel_names)? };
    let kinds = names::<RayKind>("rays", &rays.map(string_list).transpose()?.unwrap_or_else(|| vec!["primary".into(), "diffuse".into(), "shadow".into()]))?;
    let settings = BenchSettings {
        scenes,
        accels: accels.iter().map(|k| k.name().to_string()).collect(),
        all,
        rays: kinds.iter().map(|k| k.name().to_string()).collect(),
        resolution,
        repeats,
        oracle_limit,
        seed,
        heatmap_width: None,
    };
    let pool = settings::pool(threads)?;
    let report = interrupt::run(py, move |cancel| {
        settings::install(pool.as_ref(), || -> Result<BenchReport, JobError> {
            let jobs = sweep::jobs(&settings)?;
            Ok(sweep::run(&settings, &jobs, None, None, &CancelOnInterrupt(cancel))?)
        })
    })??;
    to_py(py, &report)
}

/// An image given as a path (any format raylab reads) or an (H, W, 3) float array.
fn image_arg(name: &str, v: &Bound<'_, PyAny>) -> PyResult<(u32, u32, Vec<Rgb>)> {
    if let Ok(p) = v.extract::<PathBuf>() {
        return read_image(&p, true).map_err(raylab_error);
    }
    let arr = v.cast::<PyUntypedArray>().map_err(|_| PyValueError::new_err(format!("{name}: expected a path or an (H, W, 3) float array")))?;
    let shape = arr.shape().to_vec();
    if arr.dtype().kind() != b'f' || shape.len() != 3 || shape[2] != 3 {
        return Err(PyValueError::new_err(format!("{name}: expected an (H, W, 3) float array, got dtype {} and shape {:?}", arr.dtype().str()?, shape)));
    }
    let np = v.py().import("numpy")?;
    let a = np.call_method1("ascontiguousarray", (arr, np.getattr("float32")?))?;
    let a = a.cast::<PyArrayDyn<f32>>()?.readonly();
    let px = a.as_slice()?.chunks_exact(3).map(|c| Rgb::new(c[0], c[1], c[2])).collect();
    Ok((shape[1] as u32, shape[0] as u32, px))
}

fn diff_dict<'py>(py: Python<'py>, d: &ImageDiff, w: u32, h: u32) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("width", w)?;
    out.set_item("height", h)?;
    out.set_item("mse", d.mse)?;
    out.set_item("rmse", d.rmse)?;
    out.set_item("rel_mse", d.rel_mse)?;
    // As in `raylab compare --json`: identical images have no finite PSNR.
    out.set_item("psnr_db", (d.mse > 0.0).then_some(d.psnr_db))?;
    out.set_item("max_abs", d.max_abs)?;
    out.set_item("pixels", d.pixels)?;
    out.set_item("excluded", d.excluded)?;
    Ok(out)
}

/// `raylab.compare`: MSE, RMSE, relative MSE, PSNR and max |diff| of two images.
#[pyfunction]
#[pyo3(signature = (a, b, *, exclude_bright=None))]
pub fn compare<'py>(py: Python<'py>, a: &Bound<'py, PyAny>, b: &Bound<'py, PyAny>, exclude_bright: Option<f32>) -> PyResult<Bound<'py, PyDict>> {
    if let Some(t) = exclude_bright.filter(|t| !(t.is_finite() && *t > 0.0)) {
        return Err(PyValueError::new_err(format!("exclude_bright: expected a finite number above 0, found {t}")));
    }
    let (w, h, pa) = image_arg("a", a)?;
    let (wb, hb, pb) = image_arg("b", b)?;
    if (w, h) != (wb, hb) {
        return Err(PyValueError::new_err(format!("the images differ in size: {w}×{h} against {wb}×{hb}")));
    }
    let d = compare_images(&pa, &pb, w, exclude_bright).map_err(raylab_error)?;
    diff_dict(py, &d, w, h)
}

/// `raylab.converge`: error against a reference as spp grows, per light-sampling strategy.
#[pyfunction]
#[pyo3(signature = (scene_path, *, reference=None, reference_spp=4096, strategies=None, spp=None, exclude_bright=None, **overrides))]
#[allow(clippy::too_many_arguments)]
pub fn converge<'py>(
    py: Python<'py>,
    scene_path: PathBuf,
    reference: Option<&Bound<'py, PyAny>>,
    reference_spp: u32,
    strategies: Option<&Bound<'py, PyAny>>,
    spp: Option<Vec<u32>>,
    exclude_bright: Option<f32>,
    overrides: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let s = settings::parse("converge", overrides)?;
    let strategy_list = names::<LightSampling>("strategies", &strategies.map(string_list).transpose()?.unwrap_or_else(|| ["uniform", "solid-angle", "bsdf", "mis"].map(String::from).to_vec()))?;
    let mut spps = spp.unwrap_or_else(|| vec![1, 2, 4, 8, 16, 32, 64, 128, 256]);
    if let Some(n) = spps.iter().find(|n| !(1..=1 << 20).contains(*n)) {
        return Err(PyValueError::new_err(format!("spp: expected whole numbers from 1 to 1048576, found {n}")));
    }
    spps.sort_unstable();
    spps.dedup();
    if let Some(t) = exclude_bright.filter(|t| !(t.is_finite() && *t > 0.0)) {
        return Err(PyValueError::new_err(format!("exclude_bright: expected a finite number above 0, found {t}")));
    }
    let reference = reference.map(|r| image_arg("reference", r)).transpose()?;
    let pool = settings::pool(s.threads)?;
    let o = Overrides { spp: Some(1), ..s.overrides };
    let (w, h, points, ref_pixels) = interrupt::run(py, move |cancel| {
        settings::install(pool.as_ref(), || -> Result<_, JobError> {
            let mut scene = raylab_loader::load_scene_or_mesh(&scene_path, &o).map_err(JobError::Load)?;
            let st = scene.settings.clone();
            if !matches!(st.integrator, IntegratorKind::Direct | IntegratorKind::Path) {
                return Err(JobError::Other(format!("light-sampling strategies differ only under the direct and path integrators; {} uses {} (pass integrator=\"direct\" or \"path\")", scene_path.display(), st.integrator)));
            }
            for &n in &spps {
                st.sampler.check_spp(n).map_err(|e| JobError::Other(format!("spp: {e}")))?;
            }
            let (w, h) = (st.width, st.height);
            let ref_pixels = match reference {
                Some((rw, rh, px)) => {
                    if (rw, rh) != (w, h) {
                        return Err(JobError::Other(format!("the reference is {rw}×{rh} but the renders are {w}×{h} (set width and height)")));
                    }
                    px
                }
                None => {
                    st.sampler.check_spp(reference_spp).map_err(|e| JobError::Other(format!("reference_spp: {e}")))?;
                    render_with(&mut scene, LightSampling::Mis, reference_spp, st.seed ^ REFERENCE_SEED_XOR).pixels
                }
            };
            scene.settings.seed = st.seed;
            let study = Study { strategies: &strategy_list, spps: &spps, time_budget: None, exclude_bright };
            let (points, _) = measure(&mut scene, &ref_pixels, &study, &mut |_| {}, &|| cancel.is_set()).map_err(JobError::Other)?;
            Ok((w, h, points, ref_pixels))
        })
    })??;
    let d = PyDict::new(py);
    let list = pyo3::types::PyList::empty(py);
    for p in &points {
        let x = PyDict::new(py);
        x.set_item("strategy", &p.strategy)?;
        x.set_item("spp", p.spp)?;
        x.set_item("seconds", p.seconds)?;
        x.set_item("mse", p.mse)?;
        x.set_item("rmse", p.rmse)?;
        x.set_item("rel_mse", p.rel_mse)?;
        list.append(x)?;
    }
    let slopes = PyDict::new(py);
    for name in strategy_names(&points) {
        slopes.set_item(name, spp_slope(&points, name))?;
    }
    d.set_item("width", w)?;
    d.set_item("height", h)?;
    d.set_item("points", list)?;
    d.set_item("slopes", slopes)?;
    d.set_item("reference", image_array(py, w, h, &ref_pixels)?)?;
    Ok(d)
}
