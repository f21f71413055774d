//! Normals, areas and angles from pairs of edges, safe at every scene scale.
//!
//! `(b - a) × (c - a)` has the square of the scene's scale, and normalising it squares that
//! again: in single precision the fourth power of an edge overflows for edges above ~4e9 and
//! underflows to 0 below ~2e-11 (the bunny's edges are ~1e-2 of its size: scaled by 1e12 or
//! 1e-10, its triangles got a zero or infinite length, their normals replaced by +y, and
//! shadow acne covered the mesh). In double precision the fourth
//! power of every finite `f32` is representable, so these are exact to an ulp of `f32` from
//! 1e-38 to 1e38.

use glam::{DVec3, Vec3};

fn d(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

/// The unit vector along `a × b`, or `None` when the edges are parallel or one is zero.
pub fn unit_cross(a: Vec3, b: Vec3) -> Option<Vec3> {
    d(a).cross(d(b)).try_normalize().map(|n| n.as_vec3())
}

/// `|a × b|`: the area of the parallelogram on `a` and `b`.
pub fn cross_length(a: Vec3, b: Vec3) -> f32 {
    d(a).cross(d(b)).length() as f32
}

/// The angle between `a` and `b` in radians (NaN when one is zero, as glam's).
pub fn angle_between(a: Vec3, b: Vec3) -> f32 {
    d(a).angle_between(d(b)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn right_at_every_scale() {
        // A right triangle with legs 3s and 4s in the plane z = 0.
        for s in [1e-15f32, 1e-12, 1e-10, 1.0, 1e10, 1e12, 1e15] {
            let (a, b) = (Vec3::new(3.0, 0.0, 0.0) * s, Vec3::new(0.0, 4.0, 0.0) * s);
            assert_eq!(unit_cross(a, b), Some(Vec3::Z), "scale {s}");
            assert_eq!(unit_cross(b, a), Some(-Vec3::Z), "scale {s}");
            let area = cross_length(a, b) as f64;
            assert!((area / (12.0 * s as f64 * s as f64) - 1.0).abs() < 1e-6, "scale {s}: {area}");
            assert!((angle_between(a, b) - std::f32::consts::FRAC_PI_2).abs() < 1e-6, "scale {s}");
            // Single precision: +y fallbacks from a zero or infinite length at the extremes.
            if s <= 1e-12 || s >= 1e10 {
                assert!(a.cross(b).try_normalize().is_none(), "scale {s}: single precision works here after all");
            }
        }
        assert_eq!(unit_cross(Vec3::X, Vec3::X * 2.0), None);
        assert_eq!(unit_cross(Vec3::ZERO, Vec3::Y), None);
    }
}
