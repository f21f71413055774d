//! Bicubic Bézier patches (the Utah teapot's 32) and their tessellation into a
//! [`TriangleMesh`] with exact normals from the patch derivatives.
//!
//! Evaluation runs in `f64`: points on an edge collapsed to a pole then round to the same
//! `f32`, so the zero-area triangles there are recognised and dropped.

use glam::DVec3;
use raylab_core::{Vec2, Vec3};

use super::TriangleMesh;

/// Subdivisions per patch side that give the common 6,320-triangle teapot
/// (32 patches × 10 × 10 quads × 2, less the 80 zero-area triangles at its two poles).
pub const DEFAULT_SUBDIVISIONS: u32 = 10;

/// A bicubic Bézier patch: `points[4 * row + col]`, `u` running along a row (across the
/// columns) and `v` across the rows, so `P(u, v) = Σ B_row(v) B_col(u) points[4 * row + col]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BezierPatch {
    pub points: [Vec3; 16],
}

/// The cubic Bernstein polynomials `B_0..B_3` at `t`.
pub fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

/// Their derivatives `dB_i/dt` at `t`.
pub fn bernstein_derivative(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [-3.0 * s * s, 3.0 * s * (1.0 - 3.0 * t), 3.0 * t * (2.0 - 3.0 * t), 3.0 * t * t]
}

/// Where a derivative vanishing along an edge becomes non-zero again: +1 into the patch
/// from the edge at 0, -1 from the edge at 1.
fn inward(t: f64) -> f64 {
    if t < 0.5 { 1.0 } else { -1.0 }
}

impl BezierPatch {
    /// `Σ bv[row] bu[col] points[4 * row + col]`.
    fn combine(&self, bu: [f64; 4], bv: [f64; 4]) -> DVec3 {
        let mut sum = DVec3::ZERO;
        for (row, wv) in bv.iter().enumerate() {
            for (col, wu) in bu.iter().enumerate() {
                sum += wv * wu * self.points[4 * row + col].as_dvec3();
            }
        }
        sum
    }

    pub fn point(&self, u: f32, v: f32) -> Vec3 {
        self.point_f64(u as f64, v as f64).as_vec3()
    }

    pub(crate) fn point_f64(&self, u: f64, v: f64) -> DVec3 {
        self.combine(bernstein(u), bernstein(v))
    }

    /// `(∂P/∂u, ∂P/∂v)`.
    pub fn derivatives(&self, u: f32, v: f32) -> (Vec3, Vec3) {
        let (du, dv, _) = self.derivatives_f64(u as f64, v as f64);
        (du.as_vec3(), dv.as_vec3())
    }

    /// `(P, ∂P/∂u, ∂P/∂v)` in double precision, for Newton's method.
    pub(crate) fn point_and_derivatives_f64(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let (bu, bv) = (bernstein(u), bernstein(v));
        (self.combine(bu, bv), self.combine(bernstein_derivative(u), bv), self.combine(bu, bernstein_derivative(v)))
    }

    /// `(∂P/∂u, ∂P/∂v, ∂²P/∂u∂v)`.
    fn derivatives_f64(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let (bu, bv) = (bernstein(u), bernstein(v));
        let (du, dv) = (bernstein_derivative(u), bernstein_derivative(v));
        (self.combine(du, bv), self.combine(bu, dv), self.combine(du, dv))
    }

    /// Unit normal along `∂P/∂u × ∂P/∂v`.
    ///
    /// Where a whole edge collapses to a point (the teapot's lid and bottom poles), the
    /// derivative along it vanishes: near the edge `v = v0`, `∂P/∂u ≈ (v − v0) ∂²P/∂u∂v`,
    /// so the normal's limit uses the mixed derivative (the tangent of the next row) in
    /// its place, with the sign of `v − v0` inside the patch; likewise for `u`. Where even
    /// that fails (two collapsed edges meeting at a corner), the normal is taken a step
    /// inside the patch.
    pub fn normal(&self, u: f32, v: f32) -> Vec3 {
        let (u, v) = (u as f64, v as f64);
        let (du, dv, duv) = self.derivatives_f64(u, v);
        let tiny = 1e-9 * self.size();
        let du = if du.length() > tiny { du } else { inward(v) * duv };
        let dv = if dv.length() > tiny { dv } else { inward(u) * duv };
        let n = du.cross(dv);
        if n.length() > 1e-9 * du.length() * dv.length() {
            return n.normalize().as_vec3();
        }
        let step = 1e-3;
        let (u, v) = (u + step * (0.5 - u), v + step * (0.5 - v));
        let (du, dv, _) = self.derivatives_f64(u, v);
        du.cross(dv).try_normalize().map_or(Vec3::Z, |n| n.as_vec3())
    }

    /// The largest extent of the control net, the scale for "vanishing" derivatives.
    pub(crate) fn size(&self) -> f64 {
        let (lo, hi) = self.points.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        (hi - lo).max_element() as f64
    }
}

/// Tessellates every patch into a `subdivisions × subdivisions` grid of quads, two
/// triangles each, wound so that their normals follow `∂P/∂u × ∂P/∂v`. Vertices carry the
/// exact patch normal and the patch's own `(u, v)`; patches do not share vertices.
/// Zero-area triangles (where an edge collapses to a pole) are dropped.
pub fn tessellate(patches: &[BezierPatch], subdivisions: u32) -> TriangleMesh {
    assert!(subdivisions > 0, "a patch needs at least one subdivision");
    let n = subdivisions;
    let side = n + 1;
    let mut mesh = TriangleMesh { name: "bezier patches".into(), ..Default::default() };
    for patch in patches {
        let base = mesh.positions.len() as u32;
        for i in 0..side {
            for j in 0..side {
                let (u, v) = (j as f32 / n as f32, i as f32 / n as f32);
                mesh.positions.push(patch.point(u, v));
                mesh.normals.push(patch.normal(u, v));
                mesh.uvs.push(Vec2::new(u, v));
            }
        }
        for i in 0..n {
            for j in 0..n {
                // a → b is +u, a → d is +v.
                let a = base + i * side + j;
                let (b, d) = (a + 1, a + side);
                let c = d + 1;
                for tri in [[a, b, c], [a, c, d]] {
                    if !is_degenerate(tri.map(|k| mesh.positions[k as usize])) {
                        mesh.indices.push(tri);
                    }
                }
            }
        }
    }
    mesh
}

/// Zero area, relative to the triangle's size (rounding can leave a pole's copies a unit
/// in the last place apart).
fn is_degenerate([a, b, c]: [Vec3; 3]) -> bool {
    let longest = (b - a).length_squared().max((c - b).length_squared()).max((a - c).length_squared());
    (b - a).cross(c - a).length() <= 1e-6 * longest
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat patch whose control points are a bilinear grid in disguise: `P(u, v) =
    /// (2u, 3v, 0)`, since cubic Bernstein weights reproduce linear functions.
    fn flat() -> BezierPatch {
        let mut points = [Vec3::ZERO; 16];
        for row in 0..4 {
            for col in 0..4 {
                points[4 * row + col] = Vec3::new(2.0 * col as f32 / 3.0, 3.0 * row as f32 / 3.0, 0.0);
            }
        }
        BezierPatch { points }
    }

    /// `flat()` with the z of the control points lifted: z = 1 on the four inner points.
    fn dome() -> BezierPatch {
        let mut p = flat();
        for k in [5, 6, 9, 10] {
            p.points[k].z = 1.0;
        }
        p
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-6
    }

    #[test]
    fn bernstein_values_and_derivatives() {
        assert_eq!(bernstein(0.5), [0.125, 0.375, 0.375, 0.125]);
        assert_eq!(bernstein(0.0), [1.0, 0.0, 0.0, 0.0]);
        // B(0.25) = (27, 27, 9, 1) / 64, B'(0.25) = (-27, 9, 15, 3) / 16.
        assert_eq!(bernstein(0.25), [27.0 / 64.0, 27.0 / 64.0, 9.0 / 64.0, 1.0 / 64.0]);
        assert_eq!(bernstein_derivative(0.25), [-27.0 / 16.0, 9.0 / 16.0, 15.0 / 16.0, 3.0 / 16.0]);
        assert_eq!(bernstein_derivative(0.5), [-0.75, -0.75, 0.75, 0.75]);
    }

    #[test]
    fn flat_patch_is_the_bilinear_map() {
        let p = flat();
        for (u, v) in [(0.0, 0.0), (0.5, 0.5), (0.25, 0.75), (1.0, 1.0)] {
            assert!(close(p.point(u, v), Vec3::new(2.0 * u, 3.0 * v, 0.0)), "{u} {v}: {}", p.point(u, v));
            let (du, dv) = p.derivatives(u, v);
            assert!(close(du, Vec3::new(2.0, 0.0, 0.0)) && close(dv, Vec3::new(0.0, 3.0, 0.0)), "{du} {dv}");
            assert!(close(p.normal(u, v), Vec3::Z));
        }
    }

    #[test]
    fn dome_point_and_tangents_by_hand() {
        let p = dome();
        // z(u, v) = Σ_{row, col ∈ {1,2}} B_row(v) B_col(u) = (B1 + B2)(u) (B1 + B2)(v).
        // At 0.5: (0.375 + 0.375)² = 0.5625; the tangents' z vanish by symmetry.
        assert!(close(p.point(0.5, 0.5), Vec3::new(1.0, 1.5, 0.5625)));
        let (du, dv) = p.derivatives(0.5, 0.5);
        assert!(close(du, Vec3::new(2.0, 0.0, 0.0)) && close(dv, Vec3::new(0.0, 3.0, 0.0)), "{du} {dv}");
        // At (0.25, 0.5): z = (36/64)(0.75) = 0.421875, ∂z/∂u = (B1' + B2')(0.25) · 0.75 = (24/16)(0.75).
        assert!(close(p.point(0.25, 0.5), Vec3::new(0.5, 1.5, 0.421875)));
        let (du, _) = p.derivatives(0.25, 0.5);
        assert!(close(du, Vec3::new(2.0, 0.0, 1.125)), "{du}");
        let want = Vec3::new(2.0, 0.0, 1.125).cross(Vec3::new(0.0, 3.0, 0.0)).normalize();
        assert!(close(p.normal(0.25, 0.5), want));
    }

    /// A cone's cap: row 0 collapsed to the apex (0, 0, 1), the other rows circling out.
    fn cone() -> BezierPatch {
        let mut points = [Vec3::ZERO; 16];
        for row in 0..4 {
            for col in 0..4 {
                let r = row as f32 / 3.0;
                let a = col as f32 / 3.0 * std::f32::consts::FRAC_PI_2;
                points[4 * row + col] = Vec3::new(r * a.cos(), r * a.sin(), 1.0 - r);
            }
        }
        BezierPatch { points }
    }

    #[test]
    fn collapsed_edge_has_the_limit_normal_not_nan() {
        let p = cone();
        for u in [0.0, 0.3, 1.0] {
            let (du, _) = p.derivatives(u, 0.0);
            assert!(du.length() < 1e-6, "∂P/∂u vanishes along the pole: {du}");
            let at_pole = p.normal(u, 0.0);
            let inside = p.normal(u, 1e-3);
            assert!(at_pole.is_finite() && (at_pole.length() - 1.0).abs() < 1e-6);
            assert!(at_pole.dot(inside) > 0.9999, "{u}: {at_pole} vs {inside}");
        }
    }

    #[test]
    fn corner_where_two_edges_collapse_steps_inside() {
        // Row 0 and column 0 all at the origin: both derivatives vanish at (0, 0).
        let mut p = dome();
        for k in [0, 1, 2, 3, 4, 8, 12] {
            p.points[k] = Vec3::ZERO;
        }
        let n = p.normal(0.0, 0.0);
        assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-6, "{n}");
        assert!(n.dot(p.normal(0.01, 0.01)) > 0.99, "{n}");
    }

    #[test]
    fn tessellation_drops_the_pole_triangles_and_follows_the_normals() {
        let mesh = tessellate(&[cone(), flat()], 4);
        assert_eq!(mesh.positions.len(), 2 * 25);
        assert_eq!(mesh.len(), 2 * 32 - 4);
        for tri in 0..mesh.len() as u32 {
            let face = mesh.winding_normal(tri);
            for k in mesh.indices[tri as usize] {
                assert!(face.dot(mesh.normals[k as usize]) > 0.5, "triangle {tri}");
            }
        }
        assert_eq!(mesh.uvs[25 + 5 + 2], Vec2::new(0.5, 0.25));
    }
}
