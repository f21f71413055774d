use glam::{Affine3A, Mat3, Vec3};

use crate::Aabb;

/// An affine transform with its inverse kept beside it: points and vectors go through the
/// matrix, normals through the inverse transpose so they stay perpendicular to surfaces
/// under non-uniform scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub m: Affine3A,
    pub inv: Affine3A,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform = Transform { m: Affine3A::IDENTITY, inv: Affine3A::IDENTITY };

    /// `None` when the matrix is singular or not finite (e.g. a zero scale).
    pub fn from_affine(m: Affine3A) -> Option<Self> {
        let det = m.matrix3.determinant();
        if !det.is_finite() || det.abs() < 1e-30 || !m.is_finite() {
            return None;
        }
        Some(Self { m, inv: m.inverse() })
    }

    pub fn translate(t: Vec3) -> Self {
        Self { m: Affine3A::from_translation(t), inv: Affine3A::from_translation(-t) }
    }

    pub fn scale(s: Vec3) -> Option<Self> {
        Self::from_affine(Affine3A::from_scale(s))
    }

    /// Rotation by `degrees` about `axis` (right-handed).
    pub fn rotate(axis: Vec3, degrees: f32) -> Option<Self> {
        let axis = axis.try_normalize()?;
        Self::from_affine(Affine3A::from_axis_angle(axis, degrees.to_radians()))
    }

    /// First `self`, then `next`.
    pub fn then(self, next: Transform) -> Self {
        Self { m: next.m * self.m, inv: self.inv * next.inv }
    }

    pub fn is_identity(&self) -> bool {
        self.m == Affine3A::IDENTITY
    }

    #[inline]
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.m.transform_point3(p)
    }

    #[inline]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.m.transform_vector3(v)
    }

    /// A normal, by the inverse transpose; not renormalised.
    #[inline]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        let inv3: Mat3 = self.inv.matrix3.into();
        inv3.transpose() * n
    }

    pub fn bounds(&self, b: &Aabb) -> Aabb {
        if b.is_empty() {
            return *b;
        }
        let mut out = Aabb::EMPTY;
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            out = out.grow(self.point(c));
        }
        out
    }

    /// Whether the transform flips handedness (negative determinant).
    pub fn swaps_handedness(&self) -> bool {
        self.m.matrix3.determinant() < 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_stay_perpendicular_under_nonuniform_scale() {
        let t = Transform::scale(Vec3::new(4.0, 1.0, 1.0)).unwrap().then(Transform::rotate(Vec3::Z, 30.0).unwrap());
        let tangent = Vec3::new(1.0, 1.0, 0.0);
        let normal = Vec3::new(1.0, -1.0, 0.0);
        assert!(t.vector(tangent).dot(t.normal(normal)).abs() < 1e-5);
    }

    #[test]
    fn composition_order_and_inverse() {
        let t = Transform::scale(Vec3::splat(2.0)).unwrap().then(Transform::translate(Vec3::X));
        assert!((t.point(Vec3::ONE) - Vec3::new(3.0, 2.0, 2.0)).length() < 1e-6);
        assert!((t.inv.transform_point3(Vec3::new(3.0, 2.0, 2.0)) - Vec3::ONE).length() < 1e-6);
        assert!(Transform::scale(Vec3::new(0.0, 1.0, 1.0)).is_none());
    }
}
