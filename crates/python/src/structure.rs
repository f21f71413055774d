//! Acceleration structures over geometry from a file or from NumPy vertex and index arrays,
//! their statistics, and tracing NumPy ray arrays through them in parallel.

use std::path::PathBuf;

use numpy::{PyArray1, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Primitives};
use raylab_core::Vec3;
use raylab_loader::Overrides;
use raylab_render::{Geometry, TriangleMesh};

use crate::convert::to_py;
use crate::errors::{load_error, raylab_error};
use crate::rays::{RayArrays, RayView};
use crate::settings;

/// Rays per parallel task, as in `raylab trace` (`raylab_lab::trace`).
const CHUNK: usize = 1024;

/// What tracing returns per ray, as separate arrays (structure of arrays, NumPy's layout).
struct PerRay {
    t: Vec<f32>,
    prim: Vec<i64>,
    u: Vec<f32>,
    v: Vec<f32>,
    hit: Vec<bool>,
    nodes_visited: Vec<i64>,
    prim_tests: Vec<i64>,
}

/// Closest hits (`t`, `prim`, `u`, `v`; `inf` and -1 where nothing is hit) or any hits
/// (`hit`), with each ray's own node visits and primitive tests.
fn trace_rays<P: Primitives + ?Sized>(accel: &AnyAccel, prims: &P, rays: RayView<'_>, any_hit: bool) -> PerRay {
    let n = rays.len;
    let mut nodes_visited = vec![0i64; n];
    let mut prim_tests = vec![0i64; n];
    if any_hit {
        let mut hit = vec![false; n];
        (hit.par_chunks_mut(CHUNK), nodes_visited.par_chunks_mut(CHUNK), prim_tests.par_chunks_mut(CHUNK)).into_par_iter().enumerate().for_each(|(k, (hit, nodes, tests))| {
            for i in 0..hit.len() {
                let mut c = raylab_accel::Counters::default();
                hit[i] = accel.occluded(prims, &rays.ray(k * CHUNK + i), &mut c);
                nodes[i] = c.nodes_visited as i64;
                tests[i] = c.prim_tests as i64;
            }
        });
        return PerRay { t: Vec::new(), prim: Vec::new(), u: Vec::new(), v: Vec::new(), hit, nodes_visited, prim_tests };
    }
    let (mut t, mut prim, mut u, mut v) = (vec![f32::INFINITY; n], vec![-1i64; n], vec![0f32; n], vec![0f32; n]);
    (t.par_chunks_mut(CHUNK), prim.par_chunks_mut(CHUNK), u.par_chunks_mut(CHUNK), v.par_chunks_mut(CHUNK), nodes_visited.par_chunks_mut(CHUNK), prim_tests.par_chunks_mut(CHUNK))
        .into_par_iter()
        .enumerate()
        .for_each(|(k, (t, prim, u, v, nodes, tests))| {
            for i in 0..t.len() {
                let mut c = raylab_accel::Counters::default();
                if let Some(h) = accel.intersect(prims, &rays.ray(k * CHUNK + i), &mut c) {
                    (t[i], prim[i], u[i], v[i]) = (h.t, h.prim as i64, h.u, h.v);
                }
                nodes[i] = c.nodes_visited as i64;
                tests[i] = c.prim_tests as i64;
            }
        });
    PerRay { t, prim, u, v, hit: Vec::new(), nodes_visited, prim_tests }
}

/// Traces NumPy rays through `accel` with the GIL released; returns the dict of arrays.
#[allow(clippy::too_many_arguments)]
pub fn trace_dict<'py, P: Primitives + ?Sized>(
    py: Python<'py>,
    accel: &AnyAccel,
    prims: &P,
    origins: &Bound<'py, PyAny>,
    directions: &Bound<'py, PyAny>,
    tmin: Option<&Bound<'py, PyAny>>,
    tmax: Option<&Bound<'py, PyAny>>,
    any_hit: bool,
    threads: Option<u32>,
) -> PyResult<Bound<'py, PyDict>> {
    let arrays = RayArrays::new(origins, directions, tmin, tmax)?;
    let view = arrays.view();
    let pool = settings::pool(threads)?;
    let out = py.detach(|| {
        settings::install(pool.as_ref(), || {
            view.check()?;
            Ok::<_, String>(trace_rays(accel, prims, view, any_hit))
        })
    });
    let out = out.map_err(PyValueError::new_err)?;
    let d = PyDict::new(py);
    if any_hit {
        d.set_item("hit", PyArray1::from_vec(py, out.hit))?;
    } else {
        d.set_item("t", PyArray1::from_vec(py, out.t))?;
        d.set_item("prim", PyArray1::from_vec(py, out.prim))?;
        d.set_item("u", PyArray1::from_vec(py, out.u))?;
        d.set_item("v", PyArray1::from_vec(py, out.v))?;
    }
    d.set_item("nodes_visited", PyArray1::from_vec(py, out.nodes_visited))?;
    d.set_item("prim_tests", PyArray1::from_vec(py, out.prim_tests))?;
    Ok(d)
}

/// Parses a structure name, listing the valid ones when it is unknown.
pub fn accel_kind(name: &str) -> PyResult<AccelKind> {
    name.parse::<AccelKind>().map_err(|e| PyValueError::new_err(format!("accel: {e}")))
}

/// The geometry of a scene file or bare mesh, as `raylab trace` loads it.
pub fn load_geometry(path: &std::path::Path) -> PyResult<Geometry> {
    let scene = raylab_loader::load_scene_or_mesh(path, &Overrides { accel: Some(AccelKind::None), ..Default::default() }).map_err(load_error)?;
    Ok(scene.geometry)
}

/// A triangle mesh from `(V, 3)` float vertices and `(F, 3)` integer indices.
fn mesh_from_arrays(vertices: &Bound<'_, PyAny>, indices: &Bound<'_, PyAny>) -> PyResult<TriangleMesh> {
    let (v, _) = crate::rays::floats("vertices", vertices, &[None, Some(3)], "a float array of shape (V, 3)")?;
    let positions: Vec<Vec3> = v.as_slice().chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(PyValueError::new_err(format!("vertices: vertex {i} is not finite")));
    }
    let py = indices.py();
    let arr = match indices.cast::<PyUntypedArray>() {
        Ok(a) => a.clone(),
        Err(_) => py.import("numpy")?.call_method1("asarray", (indices,))?.cast_into::<PyUntypedArray>()?,
    };
    let kind = arr.dtype().kind() as char;
    let shape = arr.shape().to_vec();
    if !matches!(kind, 'i' | 'u') || shape.len() != 2 || shape[1] != 3 {
        return Err(PyValueError::new_err(format!("indices: expected an integer array of shape (F, 3), got an array of dtype {} and shape {:?}", arr.dtype().str()?, shape)));
    }
    let np = py.import("numpy")?;
    let as_i64 = np.call_method1("ascontiguousarray", (&arr, np.getattr("int64")?))?;
    let idx = as_i64.cast::<PyArrayDyn<i64>>()?.readonly();
    let flat = idx.as_slice()?;
    let nv = positions.len() as i64;
    if let Some(k) = flat.iter().position(|&i| i < 0 || i >= nv) {
        return Err(PyValueError::new_err(format!("indices: triangle {} refers to vertex {}, but there are {nv} vertices", k / 3, flat[k])));
    }
    let indices = flat.chunks_exact(3).map(|c| [c[0] as u32, c[1] as u32, c[2] as u32]).collect();
    Ok(TriangleMesh { name: "numpy".into(), positions, indices, ..Default::default() })
}

/// An acceleration structure built over a mesh or a scene's geometry.
///
/// Build one with `raylab.build(path, accel="bvh")` or
/// `raylab.build(vertices, indices, accel="kdtree")`; then `trace` rays through it,
/// read its `stats`, or `validate` it.
#[pyclass(module = "raylab", frozen)]
pub struct Structure {
    geometry: Geometry,
    accel: AnyAccel,
    kind: AccelKind,
}

impl Structure {
    pub fn build(geometry: Geometry, kind: AccelKind, threads: Option<u32>, py: Python<'_>) -> PyResult<Self> {
        let pool = settings::pool(threads)?;
        let accel = py.detach(|| settings::install(pool.as_ref(), || AnyAccel::build(kind, &geometry, &BuildOptions::default())));
        Ok(Self { geometry, accel, kind })
    }
}

#[pymethods]
impl Structure {
    /// The structure's name (`"bvh"`, `"kdtree"`, ...).
    #[getter]
    fn accel(&self) -> &'static str {
        self.kind.name()
    }

    /// Number of primitives (triangles, spheres, curve segments, patches) it indexes.
    #[getter]
    fn primitives(&self) -> usize {
        self.geometry.len()
    }

    /// Bounds of the geometry as `((xmin, ymin, zmin), (xmax, ymax, zmax))`.
    #[getter]
    fn bounds(&self) -> ((f32, f32, f32), (f32, f32, f32)) {
        bounds_tuple(&self.geometry)
    }

    /// Build statistics (`raylab inspect --json`'s `accel` dict): build time, node and leaf
    /// counts, depth, references, leaf-size histogram, SAH cost, memory, notes.
    #[getter]
    fn stats(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        to_py(py, &self.accel.stats())
    }

    /// Checks the structure's invariants; raises `RaylabError` when one is broken.
    fn validate(&self, py: Python<'_>) -> PyResult<()> {
        py.detach(|| self.accel.validate(&self.geometry)).map_err(raylab_error)
    }

    /// The triangles as `(vertices (V, 3) float32, indices (F, 3) int64)`; for a geometry
    /// of meshes only, row `i` of `indices` is primitive `i`.
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        triangle_arrays(py, &self.geometry)
    }

    /// Traces rays: see `raylab.trace`.
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
        trace_dict(py, &self.accel, &self.geometry, origins, directions, tmin, tmax, any_hit, threads)
    }

    fn __repr__(&self) -> String {
        format!("<raylab.Structure {} over {} primitives>", self.kind.name(), self.geometry.len())
    }
}

pub fn bounds_tuple(g: &Geometry) -> ((f32, f32, f32), (f32, f32, f32)) {
    let b = g.total_bounds();
    if b.is_empty() {
        return ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0));
    }
    (b.min.into(), b.max.into())
}

/// Every mesh's triangles in one vertex and one index array, in primitive order.
pub fn triangle_arrays<'py>(py: Python<'py>, g: &Geometry) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    for m in &g.meshes {
        let base = (vertices.len() / 3) as i64;
        vertices.extend(m.positions.iter().flat_map(|p| p.to_array()));
        indices.extend(m.indices.iter().flat_map(|t| t.map(|i| base + i as i64)));
    }
    let (nv, nf) = (vertices.len() / 3, indices.len() / 3);
    Ok((PyArray1::from_vec(py, vertices).reshape([nv, 3])?.into_any(), PyArray1::from_vec(py, indices).reshape([nf, 3])?.into_any()))
}

/// `raylab.build`: a structure over a file's geometry or over NumPy arrays.
#[pyfunction]
#[pyo3(signature = (source, indices=None, *, accel="bvh", threads=None))]
pub fn build(py: Python<'_>, source: &Bound<'_, PyAny>, indices: Option<&Bound<'_, PyAny>>, accel: &str, threads: Option<u32>) -> PyResult<Structure> {
    let kind = accel_kind(accel)?;
    let geometry = match indices {
        Some(idx) => {
            let mut g = Geometry::default();
            g.add_mesh(mesh_from_arrays(source, idx)?);
            g
        }
        None => {
            let path: PathBuf = source.extract().map_err(|_| PyValueError::new_err("source: expected a path to a scene or mesh file, or a (V, 3) vertex array together with an (F, 3) index array"))?;
            py.detach(|| load_geometry(&path))?
        }
    };
    Structure::build(geometry, kind, threads, py)
}

/// `raylab.trace`: rays through the geometry of a scene or mesh file.
#[pyfunction]
#[pyo3(signature = (mesh_or_scene_path, origins, directions, *, tmin=None, tmax=None, accel=None, any_hit=false, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn trace<'py>(
    py: Python<'py>,
    mesh_or_scene_path: PathBuf,
    origins: &Bound<'py, PyAny>,
    directions: &Bound<'py, PyAny>,
    tmin: Option<&Bound<'py, PyAny>>,
    tmax: Option<&Bound<'py, PyAny>>,
    accel: Option<&str>,
    any_hit: bool,
    threads: Option<u32>,
) -> PyResult<Bound<'py, PyDict>> {
    let kind = accel_kind(accel.unwrap_or("bvh"))?;
    // Check the rays before the (possibly long) load and build.
    RayArrays::new(origins, directions, tmin, tmax)?;
    let geometry = py.detach(|| load_geometry(&mesh_or_scene_path))?;
    let s = Structure::build(geometry, kind, threads, py)?;
    trace_dict(py, &s.accel, &s.geometry, origins, directions, tmin, tmax, any_hit, threads)
}

/// `raylab.load_mesh`: the triangles of a scene or mesh file as NumPy arrays.
#[pyfunction]
pub fn load_mesh<'py>(py: Python<'py>, path: PathBuf) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let g = py.detach(|| load_geometry(&path))?;
    triangle_arrays(py, &g)
}
