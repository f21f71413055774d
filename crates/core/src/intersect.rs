//! Ray–primitive kernels shared by shapes, structures and tests.

use glam::{DVec3, Vec3};

use crate::{gamma, Ray};

/// Watertight ray–triangle intersection (Woop, Benthin & Wald, JCGT 2013).
///
/// The triangle is transformed into a ray-aligned space (shear so that the ray runs along
/// +z from the origin) and hit by 2D edge functions. Edge functions that come out exactly
/// zero are recomputed in double precision, so a ray through a shared edge or vertex hits
/// at least one of the adjacent triangles: no ray slips through a closed mesh.
///
/// Returns `(t, b1, b2)`: the distance and the barycentric weights of `p1` and `p2`
/// (the weight of `p0` is `1 - b1 - b2`), for `t` in `(ray.t_min, ray.t_max]`.
#[inline]
pub fn triangle(ray: &Ray, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<(f32, f32, f32)> {
    ShearedRay::new(ray).triangle(ray.t_min, ray.t_max, p0, p1, p2)
}

/// The per-ray part of [`triangle`]: the axis permutation and shear constants (three
/// divisions) that depend only on the direction. Structures that test many triangles
/// against one ray compute it once; [`ShearedRay::triangle`] then does exactly the
/// arithmetic of [`triangle`], so both give bit-identical answers.
#[derive(Clone, Copy, Debug)]
pub struct ShearedRay {
    pub origin: Vec3,
    /// Axis the ray mostly runs along (`kz`), and the two others in an order that keeps
    /// the winding (`kx`, `ky`).
    pub kx: usize,
    pub ky: usize,
    pub kz: usize,
    /// Shear `d[kx]/d[kz]`, `d[ky]/d[kz]` and scale `1/d[kz]`.
    pub sx: f32,
    pub sy: f32,
    pub sz: f32,
}

impl ShearedRay {
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        // Selections rather than branches (a ray's direction is as good as random), and
        // indices into the ray's own components rather than into a `Vec3` (a chain of
        // branches) or a table (stored to the stack for every ray).
        let d: &[f32; 3] = ray.dir.as_ref();
        let ad = d.map(f32::abs);
        // The axis of the largest |d|, ties to the later axis, as before.
        let (m, xy) = if ad[0] > ad[1] { (ad[0], 0) } else { (ad[1], 1) };
        let kz = if m > ad[2] { xy } else { 2 };
        // The next two axes in cyclic order, swapped when the ray runs along -kz.
        let (kx, ky) = (if kz == 2 { 0 } else { kz + 1 }, if kz == 0 { 2 } else { kz - 1 });
        let (kx, ky) = if d[kz] < 0.0 { (ky, kx) } else { (kx, ky) };
        Self { origin: ray.origin, kx, ky, kz, sx: d[kx] / d[kz], sy: d[ky] / d[kz], sz: 1.0 / d[kz] }
    }

    /// The sheared 2D coordinates `(x, y)` of vertex `p` (before the double-precision
    /// fallback): what [`ShearedRay::triangle`] computes first, exposed so that SIMD
    /// filters can reproduce it lane by lane.
    #[inline]
    pub fn project(&self, p: Vec3) -> (f32, f32) {
        let a = p - self.origin;
        (a[self.kx] - self.sx * a[self.kz], a[self.ky] - self.sy * a[self.kz])
    }

    /// [`triangle`] for this ray over `(t_min, t_max]`.
    #[inline]
    pub fn triangle(&self, t_min: f32, t_max: f32, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<(f32, f32, f32)> {
        let (kx, ky, kz, sx, sy, sz) = (self.kx, self.ky, self.kz, self.sx, self.sy, self.sz);
        let a = p0 - self.origin;
        let b = p1 - self.origin;
        let c = p2 - self.origin;
        let ax = a[kx] - sx * a[kz];
        let ay = a[ky] - sy * a[kz];
        let bx = b[kx] - sx * b[kz];
        let by = b[ky] - sy * b[kz];
        let cx = c[kx] - sx * c[kz];
        let cy = c[ky] - sy * c[kz];
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let (ax, ay, bx, by, cx, cy) = (ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64);
            u = (cx * by - cy * bx) as f32;
            v = (ax * cy - ay * cx) as f32;
            w = (bx * ay - by * ax) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let az = sz * a[kz];
        let bz = sz * b[kz];
        let cz = sz * c[kz];
        let t_scaled = u * az + v * bz + w * cz;
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        // A hit this close to the origin may be rounding error of a ray leaving this very
        // triangle: reject t below its error bound (pbrt-v4 §6.8.4), which is what makes the
        // tiny offsets of `offset_ray_origin` safe. The bound grows with the vertices'
        // distance from the origin, not with t: on a huge triangle (a ±1e6 floor) a ray from
        // just above it has its true hit below the single-precision bound, so there t is
        // recomputed in double precision, whose bound is 2^29 times smaller. The choice
        // depends only on the ray and the triangle (never on t_max), so every structure and
        // the oracle get the same t whatever order they test triangles in.
        let max_zt = az.abs().max(bz.abs()).max(cz.abs());
        let max_xt = ax.abs().max(bx.abs()).max(cx.abs());
        let max_yt = ay.abs().max(by.abs()).max(cy.abs());
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let delta_t = t_error_bound(max_xt, max_yt, max_zt, max_e, inv_det.abs(), gamma);
        // `t_scaled` is an edge function (a squared distance) times a depth: the cube of the
        // vertices' distance from the origin, which overflows single precision from ~7e12
        // (a ray over a ±8e12 floor in a scene scaled by 1e12 missed it). Double precision
        // has the range.
        let t = if !(t.is_finite() && delta_t.is_finite()) {
            self.triangle_t_f64(p0, p1, p2)?
        } else if t > delta_t {
            t
        } else if t < -delta_t {
            return None;
        } else {
            self.triangle_t_f64(p0, p1, p2)?
        };
        if !(t > t_min && t <= t_max) {
            return None;
        }
        Some((t, v * inv_det, w * inv_det))
    }

    /// The distance to the plane of `p0 p1 p2` in double precision (the arithmetic of
    /// [`ShearedRay::triangle`] on the same shear), or `None`
    /// when it is within its own error bound of zero or behind the origin: the fallback for
    /// hits too close for the single-precision bound to decide.
    #[cold]
    fn triangle_t_f64(&self, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<f32> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        // The single-precision shear constants define the transform the edge functions used;
        // their rounding only turns the ray by an ulp about its origin, which changes t by
        // an ulp of t, not of the vertices' distance as the f32 arithmetic does.
        let (sx, sy, sz) = (self.sx as f64, self.sy as f64, self.sz as f64);
        let o = self.origin.as_dvec3();
        let (a, b, c) = (p0.as_dvec3() - o, p1.as_dvec3() - o, p2.as_dvec3() - o);
        let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
        let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
        let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let (az, bz, cz) = (sz * a[kz], sz * b[kz], sz * c[kz]);
        let inv_det = 1.0 / det;
        let t = (u * az + v * bz + w * cz) * inv_det;
        let max_zt = az.abs().max(bz.abs()).max(cz.abs());
        let max_xt = ax.abs().max(bx.abs()).max(cx.abs());
        let max_yt = ay.abs().max(by.abs()).max(cy.abs());
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let delta_t = t_error_bound(max_xt, max_yt, max_zt, max_e, inv_det.abs(), gamma_f64);
        (t > delta_t).then_some(t as f32)
    }
}

/// pbrt-v4's conservative bound (§6.8.4) on the absolute error of the watertight kernel's
/// `t`, from the largest sheared coordinates and edge function, in the precision of `T`
/// with its `γₙ`.
#[inline(always)]
fn t_error_bound<T>(max_xt: T, max_yt: T, max_zt: T, max_e: T, inv_det_abs: T, gamma: fn(u32) -> T) -> T
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Mul<Output = T> + From<f32>,
{
    let delta_z = gamma(3) * max_zt;
    let delta_x = gamma(5) * (max_xt + max_zt);
    let delta_y = gamma(5) * (max_yt + max_zt);
    let delta_e = T::from(2.0) * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    T::from(3.0) * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det_abs
}

/// [`gamma`] in double precision.
fn gamma_f64(n: u32) -> f64 {
    let e = f64::EPSILON * 0.5;
    (n as f64 * e) / (1.0 - n as f64 * e)
}

/// Ray–sphere intersection, nearest root in `(ray.t_min, ray.t_max]`.
///
/// The discriminant is computed as `r² - |l|²` with `l` the offset from the centre to the
/// ray's closest approach (Hearn & Baker; Haines et al., Ray Tracing Gems ch. 7), which stays
/// accurate when the sphere is small and far away, unlike `b² - 4ac`.
#[inline]
pub fn sphere(ray: &Ray, center: Vec3, radius: f32) -> Option<f32> {
    let oc = ray.origin - center;
    let a = ray.dir.length_squared();
    let half_b = oc.dot(ray.dir);
    let l = oc - (half_b / a) * ray.dir;
    let disc = a * (radius * radius - l.length_squared());
    if disc < 0.0 {
        return None;
    }
    // Numerically stable roots: q has the sign of -half_b, so no cancellation.
    let q = -half_b - disc.sqrt().copysign(half_b);
    let (mut t0, mut t1) = (q / a, if q != 0.0 { oc.length_squared().mul_add(1.0, -radius * radius) / q } else { q / a });
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    if t0 > ray.t_min && t0 <= ray.t_max {
        Some(t0)
    } else if t1 > ray.t_min && t1 <= ray.t_max {
        Some(t1)
    } else {
        None
    }
}

/// Double-precision reference of [`triangle`]'s plane distance, for tests.
pub fn triangle_plane_t(ray: &Ray, p0: Vec3, p1: Vec3, p2: Vec3) -> f64 {
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let (p0, p1, p2): (DVec3, DVec3, DVec3) = (p0.as_dvec3(), p1.as_dvec3(), p2.as_dvec3());
    let n = (p1 - p0).cross(p2 - p0);
    n.dot(p0 - o) / n.dot(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> (Vec3, Vec3, Vec3) {
        (Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0))
    }

    #[test]
    fn rays_leaving_a_triangle_do_not_hit_it_again() {
        // A ground quad's triangle at y = 0 and a ray that left it with the smallest offset
        // `offset_ray_origin` gives at y = 0 (one ulp: 1e-45). Without the t error bound
        // the shear rounds this to a hit at t ≈ 2e-8 (found by `raylab bench` on the bunny).
        let (a, b, c) = (Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, 5.0));
        let r = Ray::new(Vec3::new(-3.360861, 1e-45, -4.7802467), Vec3::new(0.5225498, 0.35702893, -0.7742558));
        assert_eq!(triangle(&r, a, b, c), None);
        // The same ray pointing down still hits, at the hand-computed distance 1e-45 / dy.
        let down = Ray::new(Vec3::new(-3.360861, 1.0, -4.7802467), Vec3::new(0.5225498, -0.35702893, 0.7742558));
        let (t, _, _) = triangle(&down, a, b, c).unwrap();
        assert!((t - 1.0 / 0.35702893).abs() < 1e-5, "{t}");
    }

    #[test]
    fn triangle_interior_hit_hand_computed() {
        let (a, b, c) = tri();
        let r = Ray::new(Vec3::new(0.25, 0.5, 2.0), Vec3::new(0.0, 0.0, -1.0));
        let (t, b1, b2) = triangle(&r, a, b, c).unwrap();
        assert!((t - 2.0).abs() < 1e-6);
        assert!((b1 - 0.25).abs() < 1e-6 && (b2 - 0.5).abs() < 1e-6);
        // From behind: triangles are two-sided.
        let r = Ray::new(Vec3::new(0.25, 0.5, -3.0), Vec3::new(0.0, 0.0, 1.0));
        assert!((triangle(&r, a, b, c).unwrap().0 - 3.0).abs() < 1e-6);
    }

    #[test]
    fn triangle_edges_and_vertices_are_hit() {
        let (a, b, c) = tri();
        for p in [Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.5, 0.5, 0.0), a, b, c] {
            let r = Ray::new(p + Vec3::Z, -Vec3::Z);
            let (t, ..) = triangle(&r, a, b, c).unwrap_or_else(|| panic!("missed {p}"));
            assert!((t - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn triangle_misses_and_interval() {
        let (a, b, c) = tri();
        let r = Ray::new(Vec3::new(0.6, 0.6, 1.0), -Vec3::Z);
        assert!(triangle(&r, a, b, c).is_none());
        let r = Ray::segment(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 0.0, 0.5);
        assert!(triangle(&r, a, b, c).is_none());
        // Degenerate (zero-area) triangle: never hit.
        let r = Ray::new(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z);
        assert!(triangle(&r, a, b, b).is_none());
        // Ray in the triangle's plane: no hit.
        let r = Ray::new(Vec3::new(-1.0, 0.2, 0.0), Vec3::X);
        assert!(triangle(&r, a, b, c).is_none());
    }

    /// pbrt-v4's bound (§6.8.4) written out for max |x'| = 1, |y'| = 2, |z'| = 3, max |e| = 4,
    /// 1/|det| = 0.5: δz = 3γ₃, δx = γ₅(1 + 3), δy = γ₅(2 + 3), δe = 2(γ₂·1·2 + δy·1 + δx·2),
    /// δt = 3(γ₃·4·3 + δe·3 + δz·4)·0.5 = 36γ₃ + 18γ₂ + 117γ₅.
    #[test]
    fn t_error_bound_is_pbrts_formula() {
        let g = |n: f64| n * 2f64.powi(-53) / (1.0 - n * 2f64.powi(-53));
        for n in [1u32, 2, 3, 5, 7] {
            assert_eq!(gamma_f64(n), g(n as f64), "γ{n}");
        }
        let expected = 36.0 * g(3.0) + 18.0 * g(2.0) + 117.0 * g(5.0);
        let bound = t_error_bound(1.0, 2.0, 3.0, 4.0, 0.5, gamma_f64);
        assert!((bound - expected).abs() <= 1e-12 * expected, "{bound} vs {expected}");
        let bound32 = t_error_bound(1.0f32, 2.0, 3.0, 4.0, 0.5, gamma);
        let expected32 = 36.0 * gamma(3) + 18.0 * gamma(2) + 117.0 * gamma(5);
        assert!((bound32 - expected32).abs() <= 1e-5 * expected32, "{bound32} vs {expected32}");
    }

    #[test]
    fn sphere_hand_computed() {
        let r = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        assert!((sphere(&r, Vec3::ZERO, 1.0).unwrap() - 4.0).abs() < 1e-6);
        // From inside: the far root.
        let r = Ray::new(Vec3::ZERO, Vec3::Z);
        assert!((sphere(&r, Vec3::ZERO, 2.0).unwrap() - 2.0).abs() < 1e-6);
        // Tangent ray at distance exactly r: hits at t = 5.
        let r = Ray::new(Vec3::new(1.0, 0.0, -5.0), Vec3::Z);
        assert!((sphere(&r, Vec3::ZERO, 1.0).unwrap() - 5.0).abs() < 1e-3);
        let r = Ray::new(Vec3::new(1.01, 0.0, -5.0), Vec3::Z);
        assert!(sphere(&r, Vec3::ZERO, 1.0).is_none());
        // Small sphere far away keeps its precision.
        let r = Ray::new(Vec3::ZERO, Vec3::Z);
        let t = sphere(&r, Vec3::new(0.0, 0.0, 1e4), 1e-2).unwrap();
        assert!((t - (1e4 - 1e-2)).abs() < 1e-2 * 1e-2, "{t}");
        // Non-normalised direction: t in units of dir.
        let r = Ray::new(Vec3::new(0.0, 0.0, -5.0), 2.0 * Vec3::Z);
        assert!((sphere(&r, Vec3::ZERO, 1.0).unwrap() - 2.0).abs() < 1e-6);
    }
}
