use glam::Vec3;

/// A ray `origin + t * dir`, valid for `t` in the open-closed range `(t_min, t_max]`.
///
/// The valid interval travels with the ray (the `interval` idea of *Ray Tracing in One
/// Weekend*): shadow rays stop short of the light, and traversal shrinks `t_max` to the
/// closest hit found so far. `dir` need not be normalised; `t` is measured in units of `dir`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub t_min: f32,
    pub t_max: f32,
}

impl Ray {
    /// A ray over `(0, ∞)`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self { origin, dir, t_min: 0.0, t_max: f32::INFINITY }
    }

    pub fn segment(origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self {
        Self { origin, dir, t_min, t_max }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }

    /// Reciprocal direction for slab tests. `-0` becomes `+0` first, so a zero component
    /// gives `+∞`: a slab test then sees `0 × ∞ = NaN` only for a ray lying in a slab's
    /// plane, and [`crate::Aabb::intersect`] ignores NaN bounds, keeping such rays inside.
    #[inline]
    pub fn inv_dir(&self) -> Vec3 {
        Vec3::ONE / (self.dir + Vec3::ZERO)
    }

    /// True when every component is finite and the interval is not inverted.
    pub fn is_valid(&self) -> bool {
        self.origin.is_finite() && self.dir.is_finite() && self.dir != Vec3::ZERO && !self.t_min.is_nan() && !self.t_max.is_nan()
    }
}
