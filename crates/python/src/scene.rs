//! Scenes from Python: load any scene file raylab reads, inspect it, change its settings,
//! render it (image and AOVs) with the GIL released and Ctrl-C honoured.

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use raylab_accel::{Accel, Primitives};
use raylab_loader::Overrides;
use raylab_render::settings::{SettingValue, SETTINGS};
use raylab_render::film::image_out::Aov;
use raylab_render::{IntegratorKind, RenderOutput, Scene as RScene};

use crate::convert::{image_array, scalar_array, to_py};
use crate::errors::load_error;
use crate::settings::{self, Settings};
use crate::structure::{bounds_tuple, trace_dict, triangle_arrays};
use crate::interrupt;

/// Loads a scene file or bare mesh, or the embedded default scene when `path` is `None`.
pub fn load(path: Option<&std::path::Path>, o: &Overrides) -> PyResult<RScene> {
    match path {
        Some(p) => raylab_loader::load_scene_or_mesh(p, o),
        None => raylab_loader::default_scene(o),
    }
    .map_err(load_error)
}

/// Renders `scene` on a worker thread (in a pool of `threads` when given) while polling
/// for Ctrl-C.
pub fn render_interruptible(py: Python<'_>, scene: Arc<RScene>, threads: Option<u32>) -> PyResult<RenderOutput> {
    let pool = settings::pool(threads)?;
    let out = interrupt::run(py, move |cancel| settings::install(pool.as_ref(), || raylab_render::render_until(&scene, &|_| {}, cancel.flag())))?;
    // `None` only when cancelled, and then `run` has already returned the signal's exception.
    out.ok_or_else(|| pyo3::exceptions::PyKeyboardInterrupt::new_err("render cancelled"))
}

/// An AOV `Scene.render(aovs=...)` accepts: the CLI's `--aovs` and the two heat maps.
#[derive(Clone, Copy)]
enum PyAov {
    /// Rendered by its own integrator.
    Integrator(IntegratorKind),
    /// The beauty render's per-pixel variance of luminance.
    Variance,
}

/// The valid AOV names, as the CLI's `--aovs` spells them, then the heat maps.
const AOV_NAMES: &str = "albedo, normal, depth, variance, heatmap, heatmap-tests";

/// An AOV by name; `normals` (the integrator's name, and this module's before the CLI had
/// `--aovs`) stays an alias of `normal`.
fn parse_aov(name: &str) -> PyResult<PyAov> {
    let aov = match name {
        "normals" => Some(PyAov::Integrator(IntegratorKind::Normals)),
        "heatmap" => Some(PyAov::Integrator(IntegratorKind::Heatmap)),
        "heatmap-tests" => Some(PyAov::Integrator(IntegratorKind::HeatmapTests)),
        _ => name.parse::<Aov>().ok().map(|a| a.integrator().map_or(PyAov::Variance, PyAov::Integrator)),
    };
    aov.ok_or_else(|| PyValueError::new_err(format!("aovs: unknown AOV `{name}` (valid: {AOV_NAMES})")))
}

/// A scene loaded from a file (any format raylab reads), or the default scene.
///
/// `Scene(path=None, **overrides)` takes the overrides `raylab render` takes as flags
/// (`spp`, `width`, `height`, `accel`, `integrator`, ...). Read `counts`, `bounds`,
/// `memory`, `settings` and `accel_stats`; change settings with `set(**overrides)`;
/// `render()` returns the image as an (H, W, 3) float32 array.
#[pyclass(module = "raylab")]
pub struct Scene {
    inner: Arc<RScene>,
    path: Option<PathBuf>,
    settings: Settings,
}

impl Scene {
    /// The scene for changing: reloaded when an interrupted render still holds it.
    fn scene_mut(&mut self, py: Python<'_>) -> PyResult<&mut RScene> {
        if Arc::get_mut(&mut self.inner).is_none() {
            let (p, o) = (self.path.clone(), self.settings.overrides.clone());
            self.inner = Arc::new(py.detach(|| load(p.as_deref(), &o))?);
        }
        Ok(Arc::get_mut(&mut self.inner).expect("just made unique"))
    }

    fn render_with(&mut self, py: Python<'_>, integrator: Option<IntegratorKind>, threads: Option<u32>) -> PyResult<RenderOutput> {
        let saved = self.inner.settings.integrator;
        if let Some(k) = integrator {
            self.scene_mut(py)?.settings.integrator = k;
        }
        let out = render_interruptible(py, self.inner.clone(), threads);
        if integrator.is_some() {
            // Unique again unless the render was interrupted; then the next change reloads.
            if let Some(s) = Arc::get_mut(&mut self.inner) {
                s.settings.integrator = saved;
            } else {
                self.settings.overrides.integrator = Some(saved);
            }
        }
        out
    }
}

#[pymethods]
impl Scene {
    #[new]
    #[pyo3(signature = (path=None, **overrides))]
    fn new(py: Python<'_>, path: Option<PathBuf>, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let settings = settings::parse("Scene", overrides)?;
        let pool = settings::pool(settings.threads)?;
        let o = settings.overrides.clone();
        let scene = py.detach(|| settings::install(pool.as_ref(), || load(path.as_deref(), &o)))?;
        Ok(Self { inner: Arc::new(scene), path, settings })
    }

    /// The file it was loaded from (`None` for the default scene).
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.path.clone()
    }

    /// The render settings as a dict of names and values, as `raylab inspect` shows them.
    #[getter]
    fn settings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.inner.settings;
        let d = PyDict::new(py);
        for spec in SETTINGS {
            match s.get(spec.key) {
                Some(SettingValue::Integer(n)) => d.set_item(spec.key, n)?,
                Some(SettingValue::Name(name)) => d.set_item(spec.key, name)?,
                None => {}
            }
        }
        d.set_item("threads", self.settings.threads)?;
        Ok(d)
    }

    /// Changes settings, named like `raylab render`'s flags. The image size and the light
    /// grid reload the scene (the camera and light sampler depend on them), `accel`
    /// rebuilds the structure, the others apply at once.
    #[pyo3(signature = (**overrides))]
    fn set(&mut self, py: Python<'_>, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
        let new = settings::parse("set", overrides)?;
        let merged = settings::merge(&self.settings.overrides, &new.overrides);
        let threads = new.threads.or(self.settings.threads);
        let n = &new.overrides;
        if n.width.is_some() || n.height.is_some() || n.light_cells.is_some() {
            let p = self.path.clone();
            let pool = settings::pool(threads)?;
            let scene = py.detach(|| settings::install(pool.as_ref(), || load(p.as_deref(), &merged)))?;
            self.inner = Arc::new(scene);
        } else {
            let mut s = self.inner.settings.clone();
            n.apply(&mut s);
            // As on load (and in the CLI): a non-square count is rounded up for the jittered sampler.
            if let Some(note) = raylab_loader::build::round_up_jittered_spp(&mut s) {
                eprintln!("note: {note}");
            }
            s.sampler.check_spp(s.spp).map_err(|e| PyValueError::new_err(format!("spp: {e}")))?;
            let rebuild = n.accel.is_some_and(|k| k != self.inner.settings.accel);
            let pool = settings::pool(threads)?;
            let scene = self.scene_mut(py)?;
            scene.settings = s;
            if rebuild {
                py.detach(|| settings::install(pool.as_ref(), || scene.build_accel(&merged.build.clone().unwrap_or_default())));
            }
        }
        self.settings = Settings { overrides: merged, threads };
        Ok(())
    }

    /// What the scene holds: shapes, primitives by kind, materials, textures, lights.
    #[getter]
    fn counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &*self.inner;
        let g = &s.geometry;
        let d = PyDict::new(py);
        d.set_item("shapes", g.meshes.len() + g.spheres.len() + g.curves.len() + g.patch_sets.len())?;
        d.set_item("primitives", g.len())?;
        d.set_item("triangles", g.triangle_count())?;
        d.set_item("spheres", g.spheres.len())?;
        d.set_item("meshes", g.meshes.len())?;
        d.set_item("curves", g.curves.len())?;
        d.set_item("curve_segments", g.curves.iter().map(|c| c.len()).sum::<usize>())?;
        d.set_item("patches", g.patch_sets.iter().map(|p| p.len()).sum::<usize>())?;
        d.set_item("materials", s.materials.len())?;
        d.set_item("textures", s.textures.len())?;
        d.set_item("lights", s.lights.len())?;
        d.set_item("area_light_primitives", s.area_lights.len())?;
        Ok(d)
    }

    /// Bounds of the geometry as `((xmin, ymin, zmin), (xmax, ymax, zmax))`.
    #[getter]
    fn bounds(&self) -> ((f32, f32, f32), (f32, f32, f32)) {
        bounds_tuple(&self.inner.geometry)
    }

    /// Memory in bytes: `geometry`, `textures` (image texels) and `accel` (the structure),
    /// counted as `raylab inspect` counts them.
    #[getter]
    fn memory<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &*self.inner;
        let g = &s.geometry;
        let geometry = g.meshes.iter().map(|m| m.positions.len() * 12 + m.normals.len() * 12 + m.uvs.len() * 8 + m.tangents.len() * 16 + m.indices.len() * 12).sum::<usize>()
            + g.spheres.len() * std::mem::size_of::<raylab_render::Sphere>()
            + g.curves.iter().map(|c| c.memory_bytes()).sum::<usize>()
            + g.patch_sets.iter().map(|p| p.memory_bytes()).sum::<usize>()
            + g.len() * 8;
        let textures: usize = s
            .textures
            .iter()
            .map(|t| match t {
                raylab_render::Texture::Image(i) => i.width() as usize * i.height() as usize * std::mem::size_of::<raylab_core::Rgb>(),
                _ => 0,
            })
            .sum();
        let d = PyDict::new(py);
        d.set_item("geometry", geometry)?;
        d.set_item("textures", textures)?;
        d.set_item("accel", s.accel().stats().memory_bytes)?;
        Ok(d)
    }

    /// Statistics of the scene's acceleration structure (see `Structure.stats`).
    #[getter]
    fn accel_stats(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        to_py(py, &self.inner.accel().stats())
    }

    /// The triangles of the scene's meshes as `(vertices, indices)` arrays.
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        triangle_arrays(py, &self.inner.geometry)
    }

    /// Renders with the current settings. Returns the image as an (H, W, 3) float32 array
    /// of linear radiance, row 0 at the top; with `aovs` (any of "albedo", "normal",
    /// "depth", "variance", "heatmap", "heatmap-tests"; "normals" is an alias of "normal"), a
    /// dict with "image" and one array per AOV under the name given: (H, W, 3), and (H, W)
    /// for "variance".
    /// The GIL is released while rendering; Ctrl-C raises KeyboardInterrupt.
    #[pyo3(signature = (*, aovs=None, threads=None))]
    fn render<'py>(&mut self, py: Python<'py>, aovs: Option<Vec<String>>, threads: Option<u32>) -> PyResult<Bound<'py, PyAny>> {
        let threads = threads.or(self.settings.threads);
        let kinds = aovs.as_ref().map(|names| names.iter().map(|n| parse_aov(n)).collect::<PyResult<Vec<_>>>()).transpose()?;
        let out = self.render_with(py, None, threads)?;
        let image = image_array(py, out.width, out.height, &out.pixels)?;
        let Some(kinds) = kinds else { return Ok(image) };
        let d = PyDict::new(py);
        d.set_item("image", image)?;
        for (k, name) in kinds.iter().zip(aovs.iter().flatten()) {
            let array = match *k {
                PyAov::Integrator(kind) => {
                    let o = self.render_with(py, Some(kind), threads)?;
                    image_array(py, o.width, o.height, &o.pixels)?
                }
                PyAov::Variance => scalar_array(py, out.width, out.height, &out.variance)?,
            };
            d.set_item(name, array)?;
        }
        Ok(d.into_any())
    }

    /// Traces rays through the scene's own structure: see `raylab.trace`.
    #[pyo3(signature = (origins, directions, *, tmin=None, tmax=None, any_hit=false, threads=None))]
    #[allow(clippy::too_many_arguments)]
    fn trace<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        any_hit: bool,
        threads: Option<u32>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let s = &*self.inner;
        trace_dict(py, s.accel(), &s.geometry, origins, directions, tmin, tmax, any_hit, threads.or(self.settings.threads))
    }

    fn __repr__(&self) -> String {
        let s = &self.inner.settings;
        let name = self.path.as_ref().map_or("the default scene".to_string(), |p| p.display().to_string());
        format!("<raylab.Scene {name}: {} primitives, {}×{}, {} spp, {}, accel {}>", self.inner.geometry.len(), s.width, s.height, s.spp, s.integrator, s.accel)
    }
}

/// `raylab.render`: the image `raylab render -o x.pfm` writes, as an (H, W, 3) array.
#[pyfunction]
#[pyo3(signature = (scene_path=None, **overrides))]
pub fn render<'py>(py: Python<'py>, scene_path: Option<PathBuf>, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Bound<'py, PyAny>> {
    let settings = settings::parse("render", overrides)?;
    let pool = settings::pool(settings.threads)?;
    let o = settings.overrides.clone();
    // Loading and building run in the pool too, as in the CLI.
    let scene = py.detach(|| settings::install(pool.as_ref(), || load(scene_path.as_deref(), &o)))?;
    let out = render_interruptible(py, Arc::new(scene), settings.threads)?;
    image_array(py, out.width, out.height, &out.pixels)
}
