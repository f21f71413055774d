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
