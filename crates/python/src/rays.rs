//! Ray arrays from NumPy: `(N, 3)` origins and directions and optional per-ray `tmin`,
//! `tmax`. A C-contiguous float32 array is read in place (no copy); other float arrays
//! (float64, strided views) and Python sequences are converted once; any other dtype or
//! shape is a `ValueError` naming the argument.

use numpy::{PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use raylab_core::{Ray, Vec3};

/// Float32 values either borrowed from a NumPy array or converted into a vector.
pub enum Floats<'py> {
    Borrowed(PyReadonlyArrayDyn<'py, f32>),
    Owned(Vec<f32>),
}

impl Floats<'_> {
    pub fn as_slice(&self) -> &[f32] {
        match self {
            // Checked C-contiguous when the variant was chosen.
            Floats::Borrowed(a) => a.as_slice().expect("checked C-contiguous"),
            Floats::Owned(v) => v,
        }
    }
}

fn describe(shape: &[usize]) -> String {
    format!("({})", shape.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ") + if shape.len() == 1 { "," } else { "" })
}

/// An array of floats of the given shape (`None` matches any length), as float32.
pub fn floats<'py>(name: &str, obj: &Bound<'py, PyAny>, shape: &[Option<usize>], expected: &str) -> PyResult<(Floats<'py>, Vec<usize>)> {
    let py = obj.py();
    let arr = match obj.cast::<PyUntypedArray>() {
        Ok(a) => a.clone(),
        // Lists and other sequences: NumPy's own conversion, as `np.asarray` would do.
        Err(_) => {
            let np = py.import("numpy")?;
            let a = np.call_method1("asarray", (obj,)).map_err(|e| PyValueError::new_err(format!("{name}: expected {expected}, cannot convert: {e}")))?;
            a.cast_into::<PyUntypedArray>().map_err(|_| PyValueError::new_err(format!("{name}: expected {expected}")))?
        }
    };
    let dims = arr.shape().to_vec();
    let fits = dims.len() == shape.len() && dims.iter().zip(shape).all(|(d, s)| s.is_none_or(|s| *d == s));
    let dtype = arr.dtype();
    let kind: char = dtype.kind() as char;
    if kind != 'f' || !fits {
        return Err(PyValueError::new_err(format!("{name}: expected {expected}, got an array of dtype {} and shape {}", dtype.str()?, describe(&dims))));
    }
    if let Ok(a) = arr.cast::<PyArrayDyn<f32>>() {
        let ro = a.readonly();
        // C order only: `as_slice` also accepts Fortran order, whose memory order is not
        // the rows' order.
        if a.is_c_contiguous() {
            return Ok((Floats::Borrowed(ro), dims));
        }
        return Ok((Floats::Owned(ro.as_array().iter().copied().collect()), dims));
    }
    let np = py.import("numpy")?;
    let converted = np.call_method1("ascontiguousarray", (arr, np.getattr("float32")?))?;
    let a = converted.cast::<PyArrayDyn<f32>>().map_err(|_| PyValueError::new_err(format!("{name}: expected {expected}")))?;
    Ok((Floats::Owned(a.readonly().as_slice()?.to_vec()), dims))
}

/// A `t` bound: one value for every ray, or one per ray.
pub enum Bound1<'py> {
    All(f32),
    PerRay(Floats<'py>),
}

/// The rays of one `trace` call.
pub struct RayArrays<'py> {
    origins: Floats<'py>,
    directions: Floats<'py>,
    tmin: Bound1<'py>,
    tmax: Bound1<'py>,
    pub len: usize,
}

/// A read-only view of [`RayArrays`] that can cross threads (the GIL is released while tracing).
#[derive(Clone, Copy)]
pub struct RayView<'a> {
    o: &'a [f32],
    d: &'a [f32],
    tmin: BoundView<'a>,
    tmax: BoundView<'a>,
    pub len: usize,
}

#[derive(Clone, Copy)]
enum BoundView<'a> {
    All(f32),
    PerRay(&'a [f32]),
}

impl BoundView<'_> {
    #[inline]
    fn get(self, i: usize) -> f32 {
        match self {
            BoundView::All(v) => v,
            BoundView::PerRay(s) => s[i],
        }
    }
}

impl<'py> RayArrays<'py> {
    pub fn new(origins: &Bound<'py, PyAny>, directions: &Bound<'py, PyAny>, tmin: Option<&Bound<'py, PyAny>>, tmax: Option<&Bound<'py, PyAny>>) -> PyResult<Self> {
        let (o, od) = floats("origins", origins, &[None, Some(3)], "a float array of shape (N, 3)")?;
        let n = od[0];
        let (d, dd) = floats("directions", directions, &[None, Some(3)], "a float array of shape (N, 3)")?;
        if dd[0] != n {
            return Err(PyValueError::new_err(format!("directions: expected shape ({n}, 3) like origins, got {}", describe(&dd))));
        }
        let bound = |name: &str, v: Option<&Bound<'py, PyAny>>, default: f32| -> PyResult<Bound1<'py>> {
            let Some(v) = v.filter(|v| !v.is_none()) else { return Ok(Bound1::All(default)) };
            if let Ok(x) = v.extract::<f64>() {
                if v.cast::<PyUntypedArray>().is_err() || v.cast::<PyUntypedArray>()?.ndim() == 0 {
                    return Ok(Bound1::All(x as f32));
                }
            }
            Ok(Bound1::PerRay(floats(name, v, &[Some(n)], &format!("a float or a float array of shape ({n},)"))?.0))
        };
        let tmin = bound("tmin", tmin, 0.0)?;
        let tmax = bound("tmax", tmax, f32::INFINITY)?;
        Ok(Self { origins: o, directions: d, tmin, tmax, len: n })
    }

    pub fn view(&self) -> RayView<'_> {
        fn b<'a>(b: &'a Bound1<'_>) -> BoundView<'a> {
            match b {
                Bound1::All(v) => BoundView::All(*v),
                Bound1::PerRay(f) => BoundView::PerRay(f.as_slice()),
            }
        }
        RayView { o: self.origins.as_slice(), d: self.directions.as_slice(), tmin: b(&self.tmin), tmax: b(&self.tmax), len: self.len }
    }
}

impl RayView<'_> {
    #[inline]
    pub fn ray(&self, i: usize) -> Ray {
        let (o, d) = (&self.o[3 * i..3 * i + 3], &self.d[3 * i..3 * i + 3]);
        Ray { origin: Vec3::new(o[0], o[1], o[2]), dir: Vec3::new(d[0], d[1], d[2]), t_min: self.tmin.get(i), t_max: self.tmax.get(i) }
    }

    /// The first invalid ray, by the ray-file reader's rules: finite origin and direction,
    /// a non-zero direction, no NaN bound.
    pub fn check(&self) -> Result<(), String> {
        let bad = (0..self.len).into_par_iter().with_min_len(4096).find_first(|&i| {
            let r = self.ray(i);
            !r.origin.is_finite() || !r.dir.is_finite() || r.dir == Vec3::ZERO || r.t_min.is_nan() || r.t_max.is_nan()
        });
        match bad {
            None => Ok(()),
            Some(i) => {
                let r = self.ray(i);
                let what = if !r.origin.is_finite() {
                    "its origin is not finite"
                } else if !r.dir.is_finite() {
                    "its direction is not finite"
                } else if r.dir == Vec3::ZERO {
                    "its direction is zero"
                } else {
                    "tmin or tmax is NaN"
                };
                Err(format!("ray {i} is not valid: {what}"))
            }
        }
    }
}
