//! The lab from Python: bench, compare and converge, returning the plain dicts of the JSON
//! schema (docs/bench.md) ready for pandas. The method is the CLI's: ray sets generated once
//! per scene, builds and traces repeated with a warm-up, medians, every structure checked
//! against an oracle.

use std::collections::BTreeMap;
use std::path::PathBuf;

use numpy::{PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Primitives};
use raylab_core::Rgb;
use raylab_lab::bench::{median, BenchReport, BenchResult, Machine, RayFigures};
use raylab_lab::compare::{compare as compare_images, ImageDiff};
use raylab_lab::converge::{spp_slope, strategies as strategy_names, ConvergencePoint};
use raylab_lab::{rays, RayKind, TraceResult};
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

fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("model name")).and_then(|l| l.split(':').nth(1)).map(|s| s.trim().to_string()))
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

struct BenchJob {
    scenes: Vec<Option<PathBuf>>,
    accels: Vec<AccelKind>,
    all: bool,
    kinds: Vec<RayKind>,
    resolution: u32,
    repeats: u32,
    oracle_limit: usize,
    seed: u64,
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

fn bench_scene(job: &BenchJob, path: Option<&PathBuf>, cancel: &interrupt::Cancel) -> Result<Vec<BenchResult>, JobError> {
    let name = path.map_or("default scene".to_string(), |p| p.display().to_string());
    let o = Overrides { accel: Some(AccelKind::Bvh), ..Default::default() };
    let scene = match path {
        Some(p) => raylab_loader::load_scene_or_mesh(p, &o),
        None => raylab_loader::default_scene(&o),
    }
    .map_err(JobError::Load)?;
    let prims = &scene.geometry;
    let height = ((job.resolution as f64 * scene.settings.height as f64 / scene.settings.width as f64).round() as u32).max(1);
    let sets = rays::generate(&scene, job.resolution, height, &job.kinds, job.seed);
    let oracle_kind = if prims.len() <= job.oracle_limit { AccelKind::None } else { AccelKind::Bvh };
    // As in the CLI: `all` leaves out the linear structures on scenes above the oracle limit.
    let linear = [AccelKind::None, AccelKind::Aabb];
    let accels: Vec<AccelKind> = job.accels.iter().copied().filter(|k| !(job.all && oracle_kind != AccelKind::None && linear.contains(k))).collect();
    let oracle = AnyAccel::build(oracle_kind, prims, &BuildOptions::default());
    let reference: Vec<TraceResult> = sets.iter().map(|s| raylab_lab::trace(&oracle, prims, &s.rays, s.kind.any_hit())).collect();
    let mut built = Vec::new();
    for &k in &accels {
        let mut times = Vec::new();
        let mut accel = None;
        for _ in 0..job.repeats {
            let x = AnyAccel::build(k, prims, &BuildOptions::default());
            times.push(x.stats().build_ms);
            accel = Some(x);
        }
        let accel = accel.expect("repeats >= 1");
        accel.validate(prims).map_err(|e| JobError::Other(format!("{name}: {k} failed validation: {e}")))?;
        built.push((k, accel, median(times)));
    }
    // Pass 0 is the warm-up; structures interleave within each pass.
    let mut times = vec![vec![Vec::new(); sets.len()]; built.len()];
    let mut last = vec![vec![TraceResult::default(); sets.len()]; built.len()];
    for pass in 0..=job.repeats {
        if cancel.is_set() {
            return Err(JobError::Other("interrupted".into()));
        }
        for (i, (_, accel, _)) in built.iter().enumerate() {
            for (j, s) in sets.iter().enumerate() {
                let r = raylab_lab::trace(accel, prims, &s.rays, s.kind.any_hit());
                if pass > 0 {
                    times[i][j].push(r.seconds);
                }
                last[i][j] = r;
            }
        }
    }
    let mut out = Vec::new();
    let mut mismatches = Vec::new();
    for (i, (k, accel, build_ms)) in built.iter().enumerate() {
        let stats = accel.stats();
        let mut figures = BTreeMap::new();
        for (j, s) in sets.iter().enumerate() {
            let r = last[i][j];
            if !r.agrees_with(&reference[j]) {
                mismatches.push(format!("{k} on {} rays: {} hits, t sum {} (oracle {oracle_kind}: {} hits, t sum {})", s.kind, r.hits, r.t_sum, reference[j].hits, reference[j].t_sum));
            }
            let secs = median(times[i][j].clone());
            let n = r.count.max(1) as f64;
            figures.insert(
                s.kind.name().to_string(),
                RayFigures {
                    count: r.count,
                    hits: r.hits,
                    t_sum: r.t_sum,
                    mrays_per_s: r.count as f64 / secs.max(1e-12) / 1e6,
                    node_visits_per_ray: r.counters.nodes_visited as f64 / n,
                    prim_tests_per_ray: r.counters.prim_tests as f64 / n,
                    object_tests_per_ray: r.counters.object_tests as f64 / n,
                },
            );
        }
        out.push(BenchResult { scene: name.clone(), primitives: prims.len(), accel: k.name().into(), build_ms: *build_ms, memory_bytes: stats.memory_bytes, stats, rays: figures });
    }
    if !mismatches.is_empty() {
        return Err(JobError::Other(format!("{name}: answers differ from the oracle:\n  {}", mismatches.join("\n  "))));
    }
    Ok(out)
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
    let job = BenchJob { scenes, accels, all, kinds, resolution, repeats, oracle_limit, seed };
    let pool = settings::pool(threads)?;
    let report = interrupt::run(py, move |cancel| {
        settings::install(pool.as_ref(), || -> Result<BenchReport, JobError> {
            let mut results = Vec::new();
            for p in &job.scenes {
                results.extend(bench_scene(&job, p.as_ref(), &cancel)?);
            }
            Ok(BenchReport { machine: Machine { cpu: cpu_name(), threads: rayon::current_num_threads() }, raylab_version: env!("CARGO_PKG_VERSION").into(), repeats: job.repeats, resolution: job.resolution, results })
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
            let mut render_with = |strategy: LightSampling, spp: u32, seed: u64| {
                scene.settings.light_sampling = strategy;
                scene.settings.spp = spp;
                scene.settings.seed = seed;
                raylab_render::render(&scene, &|_| {})
            };
            let ref_pixels = match reference {
                Some((rw, rh, px)) => {
                    if (rw, rh) != (w, h) {
                        return Err(JobError::Other(format!("the reference is {rw}×{rh} but the renders are {w}×{h} (set width and height)")));
                    }
                    px
                }
                None => {
                    st.sampler.check_spp(reference_spp).map_err(|e| JobError::Other(format!("reference_spp: {e}")))?;
                    // Another seed, as in the CLI: a reference sharing the renders' random
                    // streams would correlate with them and understate their error.
                    render_with(LightSampling::Mis, reference_spp, st.seed ^ 0x9e37_79b9_7f4a_7c15).pixels
                }
            };
            let mut points = Vec::new();
            for &strategy in &strategy_list {
                for &n in &spps {
                    if cancel.is_set() {
                        return Err(JobError::Other("interrupted".into()));
                    }
                    let out = render_with(strategy, n, st.seed);
                    let d = compare_images(&out.pixels, &ref_pixels, w, exclude_bright).map_err(|e| JobError::Other(format!("{strategy} at {n} spp: {e}")))?;
                    points.push(ConvergencePoint { strategy: strategy.name().into(), spp: n, seconds: out.seconds, mse: d.mse, rmse: d.rmse, rel_mse: d.rel_mse });
                }
            }
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
