use raylab_core::{intersect, Aabb, Ray, Rgb, Transform, Vec2, Vec3};
use std::f32::consts::PI;

use super::SurfaceGeometry;
use crate::material::MaterialId;

/// A sphere in object space, placed in the world by `to_world` (which may scale it
/// non-uniformly into an ellipsoid).
#[derive(Clone, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub to_world: Transform,
    pub material: MaterialId,
    /// Radiance emitted outwards, zero for spheres that do not emit.
    pub emission: Rgb,
}

impl Sphere {
    pub fn bounds(&self) -> Aabb {
        let r = Vec3::splat(self.radius);
        self.to_world.bounds(&Aabb::new(self.center - r, self.center + r))
    }

    fn object_ray(&self, ray: &Ray) -> Ray {
        if self.to_world.is_identity() {
            return *ray;
        }
        // The same `t` parametrises both rays because the direction is not renormalised.
        Ray { origin: self.to_world.inv.transform_point3(ray.origin), dir: self.to_world.inv.transform_vector3(ray.dir), ..*ray }
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let r = self.object_ray(ray);
        let t = intersect::sphere(&r, self.center, self.radius)?;
        // A root within its rounding error of 0 is the surface a spawned ray leaves, found
        // again: shadow acne when the offset origin rounds to inside the sphere. pbrt-v4
        // (§6.8.5) rejects a hit whose error interval contains 0; the near root is c / q
        // with c = |o - centre|² - r², whose absolute error is within γ(|o - centre|² + r²),
        // and |q| = |(o - centre)·d| + √disc, so `t_err` bounds its error (twice γ₉ for the
        // transform into object space and the subtraction forming `o - centre`).
        let oc = r.origin - self.center;
        let half_b = oc.dot(r.dir);
        let a = r.dir.length_squared();
        let l = oc - (half_b / a) * r.dir;
        let q = half_b.abs() + (a * (self.radius * self.radius - l.length_squared())).max(0.0).sqrt();
        let t_err = 2.0 * raylab_core::gamma(9) * (oc.length_squared() + self.radius * self.radius) / q;
        if t > t_err {
            return Some(t);
        }
        // Keep looking beyond the error band (the far side of the sphere, for a ray that enters it).
        intersect::sphere(&Ray { t_min: t_err.max(r.t_min), ..r }, self.center, self.radius)
    }

    /// Surface data at the hit distance `t`. UVs are longitude/latitude: `u` runs once
    /// around the y axis starting at -x, `v` from the south pole (0) to the north pole (1),
    /// the mapping of *Ray Tracing: The Next Week* for equirectangular maps.
    pub fn surface(&self, ray: &Ray, t: f32) -> SurfaceGeometry {
        let r = self.object_ray(ray);
        let local = (r.at(t) - self.center).try_normalize().unwrap_or(Vec3::Y);
        // Re-project onto the surface: removes the error of `o + t·d`.
        let p_obj = self.center + self.radius * local;
        let theta = (-local.y).clamp(-1.0, 1.0).acos();
        let phi = (-local.z).atan2(local.x) + PI;
        let uv = Vec2::new(phi / (2.0 * PI), theta / PI);
        // ∂p/∂u (along increasing longitude) and ∂p/∂v (towards the north pole), for tangent
        // frames and bump maps. With α = atan2(-z, x): x = ρ cos α, z = -ρ sin α, ρ = sin θ.
        let dpdu_obj = Vec3::new(local.z, 0.0, -local.x) * (2.0 * PI * self.radius);
        let rho = (local.x * local.x + local.z * local.z).sqrt();
        let dpdv_obj = if rho > 1e-6 {
            Vec3::new(-local.y * local.x / rho, rho, -local.y * local.z / rho) * (PI * self.radius)
        } else {
            Vec3::X * (PI * self.radius) // at a pole any horizontal direction will do
        };
        let n = self.to_world.normal(local).normalize();
        // Reprojection leaves a relative error of γ₅ per coordinate (pbrt-v4 §6.8.5); the
        // transform adds its own rounding (§6.8.4).
        let err_obj = raylab_core::gamma(5) * p_obj.abs();
        let p_error = if self.to_world.is_identity() {
            err_obj
        } else {
            let m = glam::Mat3::from(self.to_world.m.matrix3);
            let abs_m = glam::Mat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
            abs_m * err_obj + raylab_core::gamma(3) * (abs_m * p_obj.abs() + Vec3::from(self.to_world.m.translation).abs())
        };
        SurfaceGeometry { p: self.to_world.point(p_obj), p_error, ng: n, ns: n, uv, dpdu: self.to_world.vector(dpdu_obj), dpdv: self.to_world.vector(dpdv_obj) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(center: Vec3, radius: f32, to_world: Transform) -> Sphere {
        Sphere { center, radius, to_world, material: MaterialId(0), emission: Rgb::ZERO }
    }

    #[test]
    fn bounds_are_the_box_of_centre_plus_minus_radius_carried_into_the_world() {
        let b = sphere(Vec3::new(1.0, 2.0, 3.0), 2.0, Transform::IDENTITY).bounds();
        assert_eq!((b.min, b.max), (Vec3::new(-1.0, 0.0, 1.0), Vec3::new(3.0, 4.0, 5.0)));
        // Scaled by (2, 1, 1), then moved by +10 in x: x from 2·(-1) + 10 to 2·3 + 10.
        let to_world = Transform::scale(Vec3::new(2.0, 1.0, 1.0)).unwrap().then(Transform::translate(Vec3::new(10.0, 0.0, 0.0)));
        let b = sphere(Vec3::new(1.0, 2.0, 3.0), 2.0, to_world).bounds();
        assert_eq!((b.min, b.max), (Vec3::new(8.0, 0.0, 1.0), Vec3::new(16.0, 4.0, 5.0)));
    }

    /// Rays from just outside the surface, every value exact in f32: centre (1, 2, 0),
    /// radius 2.5, origin (2.5, 2, 2 + δ) with δ = k·2⁻²² (the spacing of f32 in [2, 4)),
    /// direction (0, 0, -4). Then o - centre = (1.5, 0, 2 + δ), the ray's offset from the
    /// centre is l = (1.5, 0, 0), and it crosses the sphere at z = ±√(2.5² - 1.5²) = ±2:
    /// near t = δ/4 = k·2⁻²⁴, far t = (4 + δ)/4. pbrt-v4's bound on the near root's
    /// error (§6.8.5, twice γ₉): 2γ₉(|o - c|² + r²)/(|(o - c)·d| + √(|d|²(r² - |l|²)))
    /// = 2γ₉·12.5/(8 + 8), 14.06·2⁻²⁴. A near root within it is taken for the surface the
    /// ray leaves (k = 13: the far root instead), one beyond it is a hit (k = 15).
    #[test]
    fn a_near_root_within_its_rounding_error_is_skipped_for_the_far_one() {
        let s = sphere(Vec3::new(1.0, 2.0, 0.0), 2.5, Transform::IDENTITY);
        let gamma9 = 9.0 * f64::from(f32::EPSILON) * 0.5 / (1.0 - 9.0 * f64::from(f32::EPSILON) * 0.5);
        let bound = 2.0 * gamma9 * (1.5f64 * 1.5 + 2.0 * 2.0 + 2.5 * 2.5) / (4.0 * 2.0 + (16.0f64 * (2.5 * 2.5 - 1.5 * 1.5)).sqrt());
        let unit = 2f64.powi(-24);
        assert!(13.0 * unit < bound && bound < 15.0 * unit, "{}", bound / unit);
        let ray = |k: f32| Ray::new(Vec3::new(2.5, 2.0, 2.0 + k * 2f32.powi(-22)), Vec3::new(0.0, 0.0, -4.0));
        // (c/q = 4δ/(16 + 4δ): δ/4 to a relative 10⁻⁶)
        let near = s.intersect(&ray(15.0)).unwrap();
        assert!((near / (15.0 * 2f32.powi(-24)) - 1.0).abs() < 1e-5, "{near}");
        let far = s.intersect(&ray(13.0)).unwrap();
        assert!((far - (1.0 + 13.0 * 2f32.powi(-24))).abs() < 1e-6, "{far}");
        // Far from the surface the near root is taken: from z = 6, t = 1 and 2.
        assert_eq!(s.intersect(&Ray::new(Vec3::new(2.5, 2.0, 6.0), Vec3::new(0.0, 0.0, -4.0))), Some(1.0));
        // A ray starting inside hits the far side.
        assert_eq!(s.intersect(&Ray::new(Vec3::new(2.5, 2.0, 0.0), Vec3::new(0.0, 0.0, -4.0))), Some(0.5));
        assert_eq!(s.intersect(&Ray::new(Vec3::new(4.5, 2.0, 6.0), Vec3::new(0.0, 0.0, -4.0))), None);
    }

    /// Hits on the axes of a sphere centred at (1, 2, 3) with radius 2, worked by hand:
    /// u = 0 at -x, ½ at +x, ¼ at +z; v = 0 at the south pole, ½ on the equator, 1 at the
    /// north pole; ∂p/∂u = 2πr·(z, 0, -x) (unit direction (x, y, z)), ∂p/∂v = πr·(0, 1, 0)
    /// on the equator and πr·x̂ at a pole; the point error γ₅·|p|.
    #[test]
    fn surface_on_the_axes_by_hand() {
        let c = Vec3::new(1.0, 2.0, 3.0);
        let s = sphere(c, 2.0, Transform::IDENTITY);
        let (pi, gamma5) = (PI, 5.0 * f32::EPSILON * 0.5 / (1.0 - 5.0 * f32::EPSILON * 0.5));
        // (direction from the centre, uv, ∂p/∂u, ∂p/∂v)
        let cases = [
            (Vec3::X, Vec2::new(0.5, 0.5), Vec3::new(0.0, 0.0, -4.0 * pi), Vec3::new(0.0, 2.0 * pi, 0.0)),
            (Vec3::Z, Vec2::new(0.25, 0.5), Vec3::new(4.0 * pi, 0.0, 0.0), Vec3::new(0.0, 2.0 * pi, 0.0)),
            (-Vec3::Z, Vec2::new(0.75, 0.5), Vec3::new(-4.0 * pi, 0.0, 0.0), Vec3::new(0.0, 2.0 * pi, 0.0)),
            (Vec3::Y, Vec2::new(0.5, 1.0), Vec3::ZERO, Vec3::new(2.0 * pi, 0.0, 0.0)),
            (-Vec3::Y, Vec2::new(0.5, 0.0), Vec3::ZERO, Vec3::new(2.0 * pi, 0.0, 0.0)),
        ];
        for (dir, uv, dpdu, dpdv) in cases {
            let ray = Ray::new(c + 5.0 * dir, -dir);
            let t = s.intersect(&ray).unwrap();
            assert_eq!(t, 3.0, "{dir}");
            let g = s.surface(&ray, t);
            let p = c + 2.0 * dir;
            assert_eq!((g.p, g.ng, g.ns), (p, dir, dir), "{dir}");
            assert!((g.uv - uv).abs().max_element() < 1e-6, "{dir}: {}", g.uv);
            assert!((g.dpdu - dpdu).length() < 1e-5, "{dir}: {}", g.dpdu);
            assert!((g.dpdv - dpdv).length() < 1e-5, "{dir}: {}", g.dpdv);
            assert!((g.p_error - gamma5 * p.abs()).length() < 1e-12, "{dir}: {}", g.p_error);
        }
        // A point off the axes: the surface point is re-projected to exactly r from the centre
        // even where o + t·d is not.
        let dir = Vec3::new(2.0, -3.0, 6.0) / 7.0;
        let ray = Ray::new(c + 5.0 * dir + Vec3::new(0.1, 0.0, 0.0), -dir);
        let g = s.surface(&ray, 3.0);
        let local = (ray.at(3.0) - c).as_dvec3().normalize();
        assert!((g.p.as_dvec3() - (c.as_dvec3() + 2.0 * local)).length() < 1e-6, "{}", g.p);
        assert!((g.ng.as_dvec3() - local).length() < 1e-6, "{}", g.ng);
    }

    /// The unit sphere scaled by (2, 1, 1) and moved to (5, 0, 0): an ellipsoid with
    /// semi-axes 2, 1, 1. A ray down z through world (5.96, 0.6) meets it over the object
    /// point P = (0.48, 0.6, 0.64) (a unit vector), at t = (4 - 0.64)/2 = 1.68. There the
    /// normal is the inverse transpose's (0.48/2, 0.6, 0.64), normalised; u and v are those
    /// of P in the parametrisation of the test below; ∂p/∂u and ∂p/∂v are its derivatives in
    /// object space, 2π(z, 0, -x) and π(-yx/ρ, ρ, -yz/ρ) with ρ = sin θ = 0.8, scaled by 2 in x.
    #[test]
    fn ellipsoid_hits_in_object_space() {
        let to_world = Transform::scale(Vec3::new(2.0, 1.0, 1.0)).unwrap().then(Transform::translate(Vec3::new(5.0, 0.0, 0.0)));
        let s = sphere(Vec3::ZERO, 1.0, to_world);
        let ray = Ray::new(Vec3::new(5.96, 0.6, 4.0), Vec3::new(0.0, 0.0, -2.0));
        let t = s.intersect(&ray).unwrap();
        assert!((t - 1.68).abs() < 1e-5, "{t}");
        let g = s.surface(&ray, t);
        assert!((g.p - Vec3::new(5.96, 0.6, 0.64)).length() < 1e-5, "{}", g.p);
        assert!((g.ng - Vec3::new(0.24, 0.6, 0.64) / 0.8272f32.sqrt()).length() < 1e-5, "{}", g.ng);
        assert_eq!(g.ng, g.ns);
        let (theta, alpha) = (g.uv.y * PI, g.uv.x * 2.0 * PI - PI);
        let p_of_uv = Vec3::new(theta.sin() * alpha.cos(), -theta.cos(), -theta.sin() * alpha.sin());
        assert!((p_of_uv - Vec3::new(0.48, 0.6, 0.64)).length() < 1e-5, "{}", g.uv);
        assert!((g.dpdu - 2.0 * PI * Vec3::new(1.28, 0.0, -0.48)).length() < 1e-4, "{}", g.dpdu);
        assert!((g.dpdv - PI * Vec3::new(-0.72, 0.8, -0.48)).length() < 1e-4, "{}", g.dpdv);
        // The error bound (pbrt-v4 §6.8.4-5): |M|·γ₅|p_obj| + γ₃(|M|·|p_obj| + |translation|),
        // |M| = diag(2, 1, 1).
        let (g3, g5) = (3.0 * f64::from(f32::EPSILON) * 0.5, 5.0 * f64::from(f32::EPSILON) * 0.5);
        let expected = [2.0 * g5 * 0.48 + g3 * (2.0 * 0.48 + 5.0), (g5 + g3) * 0.6, (g5 + g3) * 0.64];
        for (k, e) in expected.into_iter().enumerate() {
            assert!((f64::from(g.p_error[k]) - e).abs() <= 1e-3 * e, "{k}: {} vs {e}", g.p_error);
        }
        // Inside the ellipsoid's x range only because of the scaling: x = 6.5 hits, 7.5 misses.
        assert!(s.intersect(&Ray::new(Vec3::new(6.5, 0.0, 4.0), Vec3::new(0.0, 0.0, -1.0))).is_some());
        assert!(s.intersect(&Ray::new(Vec3::new(7.5, 0.0, 4.0), Vec3::new(0.0, 0.0, -1.0))).is_none());
    }

    /// ∂p/∂u and ∂p/∂v agree with finite differences of the point at `uv ± h`.
    #[test]
    fn partial_derivatives_match_finite_differences() {
        let s = Sphere { center: Vec3::new(1.0, 2.0, 3.0), radius: 2.0, to_world: Transform::IDENTITY, material: MaterialId(0), emission: Rgb::ZERO };
        let point = |u: f32, v: f32| {
            let (theta, alpha) = (v * PI, u * 2.0 * PI - PI);
            s.center + s.radius * Vec3::new(theta.sin() * alpha.cos(), -theta.cos(), -theta.sin() * alpha.sin())
        };
        for (u, v) in [(0.1, 0.3), (0.6, 0.5), (0.9, 0.8)] {
            let p = point(u, v);
            let ray = Ray::new(s.center + 2.0 * (p - s.center), s.center - p);
            let t = s.intersect(&ray).unwrap();
            let g = s.surface(&ray, t);
            assert!((g.uv - Vec2::new(u, v)).length() < 1e-4, "{}", g.uv);
            let h = 1e-3;
            let fd_u = (point(u + h, v) - point(u - h, v)) / (2.0 * h);
            let fd_v = (point(u, v + h) - point(u, v - h)) / (2.0 * h);
            assert!((g.dpdu - fd_u).length() < 1e-2 * fd_u.length(), "{} vs {fd_u}", g.dpdu);
            assert!((g.dpdv - fd_v).length() < 1e-2 * fd_v.length(), "{} vs {fd_v}", g.dpdv);
        }
    }
}
