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

    #[test]
    fn size_is_the_largest_extent_of_the_control_net() {
        // flat(): x in [0, 2], y in [0, 3], z = 0; moved to (5, −7, 9) the extents stay.
        let mut p = flat();
        assert_eq!(p.size(), 3.0);
        for q in &mut p.points {
            *q += Vec3::new(5.0, -7.0, 9.0);
        }
        assert_eq!(p.size(), 3.0);
        // One point raised by 4.5: z then spans [9, 13.5].
        p.points[7].z += 4.5;
        assert_eq!(p.size(), 4.5);
    }

    #[test]
    fn flat_patches_tessellated_by_hand() {
        // Two subdivisions: vertices at u, v ∈ {0, ½, 1}, row by row in v, at (2u, 3v, 0) (the
        // second patch moved up by 1 in z), normal ẑ, uv (u, v). Quad (i, j) has corners
        // a = 3i + j, b = a + 1 (+u), d = a + 3 (+v), c = a + 4, split into [a, b, c] and [a, c, d].
        let mut up = flat();
        for q in &mut up.points {
            q.z = 1.0;
        }
        let mesh = tessellate(&[flat(), up], 2);
        assert_eq!(mesh.name, "bezier patches");
        assert_eq!(mesh.positions.len(), 18);
        for (k, (p, (n, uv))) in mesh.positions.iter().zip(mesh.normals.iter().zip(&mesh.uvs)).enumerate() {
            let (u, v) = ((k % 3) as f32 / 2.0, (k % 9 / 3) as f32 / 2.0);
            let z = if k < 9 { 0.0 } else { 1.0 };
            assert!(close(*p, Vec3::new(2.0 * u, 3.0 * v, z)) && close(*n, Vec3::Z) && *uv == Vec2::new(u, v), "vertex {k}: {p} {n} {uv}");
        }
        let first: [[u32; 3]; 8] = [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [3, 4, 7], [3, 7, 6], [4, 5, 8], [4, 8, 7]];
        let second = first.map(|t| t.map(|k| k + 9));
        assert_eq!(mesh.indices, [first, second].concat());
        // [0, 1, 4]: (1, 0, 0) × (1, 1.5, 0) = (0, 0, 1.5), along ∂P/∂u × ∂P/∂v = (2, 0, 0) × (0, 3, 0).
        assert!(close(mesh.winding_normal(0), Vec3::Z));
    }

    #[test]
    fn degenerate_means_area_within_a_millionth_of_the_longest_edge_squared() {
        // |(b − a) × (c − a)| = twice the area = L·h for the longest edge L = 1000 and the
        // height h over it; degenerate when L·h ≤ 10⁻⁶ L², that is h ≤ 10⁻³. Far from the
        // origin (1000, 1000, 1000), and with the longest edge first, second or third.
        let a = Vec3::splat(1000.0);
        let b = a + Vec3::new(1000.0, 0.0, 0.0);
        for (h, degenerate) in [(1.5e-3, false), (0.5e-3, true)] {
            let c = Vec3::new(1500.0, 1000.0 + h, 1000.0);
            assert_eq!([is_degenerate([a, b, c]), is_degenerate([b, c, a]), is_degenerate([c, a, b])], [degenerate; 3], "h = {h}");
        }
        assert!(is_degenerate([a, a, a]) && is_degenerate([a, b, b]));
        assert!(!is_degenerate([Vec3::ZERO, Vec3::X, Vec3::Y]));
    }

    #[test]
    fn collapsed_edges_on_all_four_sides_have_the_cone_normal() {
        // cone() is P(u, v) = v·(C(u), −1) + ẑ, C the planar Bézier arc over (cos, sin)(kπ/6):
        // ∂P/∂u = v·(C′, 0) vanishes at v = 0, ∂P/∂v = (C, −1), ∂²P/∂u∂v = (C′, 0). At u = 0,
        // C = (1, 0) and C′ = 3((√3/2, ½) − (1, 0)), so the normal is along
        // (C′, 0) × (1, 0, −1) = (−C′y, C′x, −C′y).
        let c = 3.0 * (Vec3::new(0.75f32.sqrt(), 0.5, 0.0) - Vec3::X);
        let n = Vec3::new(-c.y, c.x, -c.y).normalize();
        let p = cone().points;
        // Rows reversed, P(u, 1 − v): the pole at v = 1, the surface turned over (−n). Transposed,
        // P(v, u): the pole at u = 0, turned over too. Transposed and reversed, P(v, 1 − u): the
        // pole at u = 1, −1 twice, n.
        let reversed = BezierPatch { points: std::array::from_fn(|k| p[4 * (3 - k / 4) + k % 4]) };
        let transposed = BezierPatch { points: std::array::from_fn(|k| p[4 * (k % 4) + k / 4]) };
        let both = BezierPatch { points: std::array::from_fn(|k| p[4 * (3 - k % 4) + k / 4]) };
        for (patch, (u, v), want) in [(cone(), (0.0, 0.0), n), (reversed, (0.0, 1.0), -n), (transposed, (0.0, 0.0), -n), (both, (1.0, 0.0), n)] {
            let got = patch.normal(u, v);
            assert!(close(got, want), "({u}, {v}): {got} vs {want}");
        }
    }

    #[test]
    fn vanishing_is_relative_to_the_patch_size() {
        // cone() scaled by 10 with its apex moved to the origin, and its pole row spread along ẑ by
        // 10⁻⁹ per point: ∂P/∂u = (0, 0, 3·10⁻⁹) at v = 0, under 10⁻⁹ × the size 10. It counts as
        // vanished, and the normal at the pole is the cone's (as above, scale-free); taken at face
        // value, (0, 0, 1) × ∂P/∂v = ẑ × (10, 0, −10) would give ŷ.
        let mut p = cone();
        for q in &mut p.points {
            *q = 10.0 * (*q - Vec3::Z);
        }
        for k in 0..4 {
            p.points[k] = Vec3::new(0.0, 0.0, 1e-9 * k as f32);
        }
        assert_eq!(p.size(), 10.0);
        let c = 3.0 * (Vec3::new(0.75f32.sqrt(), 0.5, 0.0) - Vec3::X);
        let want = Vec3::new(-c.y, c.x, -c.y).normalize();
        assert!(close(p.normal(0.0, 0.0), want), "{}", p.normal(0.0, 0.0));
        // A dome a tenth the size: |∂P/∂u × ∂P/∂v| = 0.06 is under |∂P/∂v| = 0.3, yet far from
        // vanishing against |∂P/∂u||∂P/∂v|; the normal is the dome's at (0.25, 0.5) exactly.
        let mut small = dome();
        for q in &mut small.points {
            *q *= 0.1;
        }
        let want = Vec3::new(2.0, 0.0, 1.125).cross(Vec3::new(0.0, 3.0, 0.0)).normalize();
        assert!(close(small.normal(0.25, 0.5), want), "{}", small.normal(0.25, 0.5));
    }

    #[test]
    fn a_corner_where_even_the_mixed_derivative_vanishes_steps_inside() {
        // Points 0, 1, 4 and 5 together: ∂P/∂u = 3(p1 − p0), ∂P/∂v = 3(p4 − p0) and
        // ∂²P/∂u∂v = 9(p5 − p4 − p1 + p0) all vanish at (0, 0), the cross product is 0 against a
        // bound of 0: a unit normal from a step inside, not 0/0.
        let mut p = dome();
        for k in [0, 1, 4, 5] {
            p.points[k] = Vec3::ZERO;
        }
        let n = p.normal(0.0, 0.0);
        assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-6 && n.dot(p.normal(0.01, 0.01)) > 0.9, "{n}");
    }

    #[test]
    fn corner_normal_is_the_limit_a_step_inside() {
        // Row 0 and column 0 at the origin: near (0, 0) only B1 B1 p5, B2(u) B1(v) p6 and
        // B1(u) B2(v) p9 count, P ≈ 9uv p5 + 9u²v (p6 − 2p5) + 9uv² (p9 − 2p5), and at u = v = ε
        // ∂P/∂u × ∂P/∂v ≈ 81ε³ p5 × (p9 − p6) = 81ε³ (2/3, 1, 1) × (−2/3, 1, 0) = 81ε³ (−1, −2/3, 4/3),
        // along (−3, −2, 4)/√29. The step of 10⁻³ towards the centre lands at ε = 5·10⁻⁴, where the
        // neglected terms tilt it by about 4·10⁻⁴ rad (cos ≥ 1 − 10⁻⁷).
        let mut p = dome();
        for k in [0, 1, 2, 3, 4, 8, 12] {
            p.points[k] = Vec3::ZERO;
        }
        let want = Vec3::new(-3.0, -2.0, 4.0) / 29f32.sqrt();
        assert!(p.normal(0.0, 0.0).dot(want) > 0.9999995, "{}", p.normal(0.0, 0.0));
        // Turned round, P(1 − u, 1 − v): the corner at (1, 1), the same normal (−1 twice).
        let turned = BezierPatch { points: std::array::from_fn(|k| p.points[15 - k]) };
        assert!(turned.normal(1.0, 1.0).dot(want) > 0.9999995, "{}", turned.normal(1.0, 1.0));
    }
}
