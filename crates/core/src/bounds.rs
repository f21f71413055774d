use glam::Vec3;

use crate::Ray;

/// An axis-aligned bounding box. The empty box has `min = +∞`, `max = -∞`, so that
/// `union` with it is the identity and every ray misses it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    pub fn new(a: Vec3, b: Vec3) -> Self {
        Self { min: a.min(b), max: a.max(b) }
    }

    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.grow(p))
    }

    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    #[inline]
    pub fn grow(self, p: Vec3) -> Self {
        Self { min: self.min.min(p), max: self.max.max(p) }
    }

    #[inline]
    pub fn union(self, o: Aabb) -> Self {
        Self { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    pub fn intersection(self, o: Aabb) -> Self {
        Self { min: self.min.max(o.min), max: self.max.min(o.max) }
    }

    #[inline]
    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    pub fn extent(&self) -> Vec3 {
        if self.is_empty() { Vec3::ZERO } else { self.max - self.min }
    }

    /// Surface area; 0 for the empty box (the SAH needs that, not NaN).
    #[inline]
    pub fn surface_area(&self) -> f32 {
        let d = self.extent();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Half the surface area: the SAH only ever compares areas, so the factor 2 is dropped.
    #[inline]
    pub fn half_area(&self) -> f32 {
        let d = (self.max - self.min).max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    pub fn volume(&self) -> f32 {
        let d = self.extent();
        d.x * d.y * d.z
    }

    /// Index of the longest axis (0, 1 or 2).
    pub fn max_axis(&self) -> usize {
        let d = self.extent();
        if d.x >= d.y && d.x >= d.z { 0 } else if d.y >= d.z { 1 } else { 2 }
    }

    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// `o` lies inside `self` (closed).
    pub fn contains_box(&self, o: &Aabb) -> bool {
        o.is_empty() || (o.min.cmpge(self.min).all() && o.max.cmple(self.max).all())
    }

    /// Position of `p` relative to the box: 0 at `min`, 1 at `max` on each axis.
    pub fn offset(&self, p: Vec3) -> Vec3 {
        let d = self.max - self.min;
        let o = p - self.min;
        Vec3::new(
            if d.x > 0.0 { o.x / d.x } else { 0.0 },
            if d.y > 0.0 { o.y / d.y } else { 0.0 },
            if d.z > 0.0 { o.z / d.z } else { 0.0 },
        )
    }

    /// Slab test (Kay & Kajiya; Williams et al. 2005) with the reciprocal direction from
    /// [`Ray::inv_dir`]. Returns the entry and exit distances clipped to `[t_min, t_max]`.
    /// Written per axis so that a NaN bound (a ray lying in a slab's plane) constrains
    /// nothing, as in pbrt, and boxes are closed: a ray grazing a face hits. The far
    /// distance is scaled by `1 + 2γ₃` (pbrt-v4 §6.8.2) so rounding never misses a box.
    #[inline]
    pub fn intersect(&self, origin: Vec3, inv_dir: Vec3, t_min: f32, t_max: f32) -> Option<(f32, f32)> {
        let (mut t0, mut t1) = (t_min, t_max);
        for a in 0..3 {
            let mut near = (self.min[a] - origin[a]) * inv_dir[a];
            let mut far = (self.max[a] - origin[a]) * inv_dir[a];
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            far *= ROBUST_FAR;
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
        }
        (t0 <= t1).then_some((t0, t1))
    }

    /// [`Aabb::intersect`] for one ray; the empty box is never hit (the hot path leaves that
    /// check to the builders, which never store empty boxes).
    pub fn intersect_ray(&self, ray: &Ray) -> Option<(f32, f32)> {
        if self.is_empty() {
            return None;
        }
        self.intersect(ray.origin, ray.inv_dir(), ray.t_min, ray.t_max)
    }

    /// The smallest sphere around the box (not the tightest sphere around its contents).
    pub fn bounding_sphere(&self) -> BoundingSphere {
        if self.is_empty() {
            return BoundingSphere { center: Vec3::ZERO, radius: -1.0 };
        }
        BoundingSphere { center: self.centroid(), radius: 0.5 * (self.max - self.min).length() }
    }
}

/// `1 + 2γ₃` with `γₙ = nε/(1-nε)`: the conservative factor of pbrt-v4's robust slab test.
const ROBUST_FAR: f32 = 1.0 + 2.0 * 3.0 * f32::EPSILON * 0.5 / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// A bounding sphere; a negative radius marks the empty sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    pub center: Vec3,
    pub radius: f32,
}

impl BoundingSphere {
    pub fn is_empty(&self) -> bool {
        self.radius < 0.0
    }

    /// The smallest sphere holding both spheres.
    pub fn union(self, o: BoundingSphere) -> Self {
        if self.is_empty() {
            return o;
        }
        if o.is_empty() {
            return self;
        }
        let d = o.center - self.center;
        let dist = d.length();
        if dist + o.radius <= self.radius {
            return self;
        }
        if dist + self.radius <= o.radius {
            return o;
        }
        // The centre lies on the segment between the centres, at t = ½(1 + (r₂ - r₁)/d);
        // clamping t and measuring the radius from the rounded centre keeps both inputs
        // inside even for nearly concentric spheres of nearly equal radii, where
        // `(radius - r₁) / d` would divide a rounding error by a tiny distance.
        let t = (0.5 * (1.0 + (o.radius - self.radius) / dist)).clamp(0.0, 1.0);
        let center = self.center + d * t;
        let radius = ((center - self.center).length() + self.radius).max((center - o.center).length() + o.radius);
        // Grow by a few ulps so that both inputs stay inside despite rounding.
        Self { center, radius: radius * (1.0 + 4.0 * f32::EPSILON) }
    }

    /// Entry and exit distances of the ray through the sphere, clipped to `(t_min, t_max)`.
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, f32)> {
        if self.is_empty() {
            return None;
        }
        let oc = ray.origin - self.center;
        let a = ray.dir.length_squared();
        let half_b = oc.dot(ray.dir);
        // Hearn & Baker form of the discriminant (Ray Tracing Gems ch. 7) for precision far away.
        let l = oc - (half_b / a) * ray.dir;
        let disc = a * (self.radius * self.radius - l.length_squared());
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        let t0 = (-half_b - s) / a;
        let t1 = (-half_b + s) / a;
        let t_near = t0.max(ray.t_min);
        let t_far = t1.min(ray.t_max);
        (t_near <= t_far).then_some((t_near, t_far))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_test_hand_computed() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let r = Ray::new(Vec3::new(-3.0, 0.5, 0.0), Vec3::X);
        let (t0, t1) = b.intersect_ray(&r).unwrap();
        assert_eq!(t0, 2.0);
        assert!((t1 - 4.0).abs() < 1e-5);
        // A ray in the plane of a face still hits (NaN-safe min/max).
        let r = Ray::new(Vec3::new(-3.0, 1.0, 0.0), Vec3::X);
        assert!(b.intersect_ray(&r).is_some());
        let r = Ray::new(Vec3::new(-3.0, -1.0, 0.0), Vec3::X);
        assert!(b.intersect_ray(&r).is_some());
        let r = Ray::new(Vec3::new(-3.0, 1.0, 0.0), Vec3::new(1.0, -0.0, 0.0));
        assert!(b.intersect_ray(&r).is_some());
        let r = Ray::new(Vec3::new(-3.0, 1.5, 0.0), Vec3::X);
        assert!(b.intersect_ray(&r).is_none());
        assert!(Aabb::EMPTY.intersect_ray(&Ray::new(Vec3::ZERO, Vec3::X)).is_none());
    }

    #[test]
    fn sphere_union_contains_both() {
        let a = BoundingSphere { center: Vec3::ZERO, radius: 1.0 };
        let b = BoundingSphere { center: Vec3::new(4.0, 0.0, 0.0), radius: 1.0 };
        let u = a.union(b);
        assert!((u.center - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-6);
        assert!((u.radius - 3.0).abs() < 1e-5);
        assert_eq!(a.union(BoundingSphere { center: Vec3::ZERO, radius: 0.5 }), a);
    }

    #[test]
    fn sphere_union_of_nearly_concentric_spheres_contains_both() {
        // The 202k-triangle dragon's sphere hierarchy failed validation on such pairs: the
        // old centre formula divided a rounding error by a distance of a few ulps.
        let mut rng = crate::rng::Pcg32::new(7, 1);
        for _ in 0..100_000 {
            let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 0.2 - 0.1;
            let r = 1e-3 + 1e-2 * rng.next_f32();
            let a = BoundingSphere { center: c, radius: r };
            let wiggle = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
            let b = BoundingSphere { center: c + wiggle * r * 1e-6, radius: r * (1.0 + 1e-6 * (rng.next_f32() - 0.5)) };
            let u = a.union(b);
            for x in [a, b] {
                assert!((x.center - u.center).length() + x.radius <= u.radius, "{a:?} ∪ {b:?} = {u:?}");
            }
        }
    }

    #[test]
    fn empty_box_has_zero_area() {
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
        assert_eq!(Aabb::EMPTY.half_area(), 0.0);
        assert!(Aabb::EMPTY.is_empty());
    }
}
