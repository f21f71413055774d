//! Ray–curve intersection by recursive subdivision in ray space (Nakamaru & Ohno 2002;
//! pbrt-v3 §9.3), ending in exact tests against a round tube.
//!
//! The cubic is moved into a frame where the ray starts at the origin and runs along +z.
//! A sub-curve whose control hull, grown by its largest radius, misses the z axis (or
//! lies outside the ray's interval) is skipped; otherwise it is halved, down to a depth at
//! which each piece is within `FLATNESS × radius` of its chord. Each leaf is then a cone
//! frustum (a tapered cylinder) along the chord, plus a sphere at each end: the spheres
//! close the wedges between consecutive frusta at a bend, and round the strand's two ends.
//! Unlike pbrt's flat ribbons this is a closed round tube, which is what the tessellated
//! `tube` mode draws too.
//!
//! The tube is the *union* of these pieces, so a root on one piece counts only where it is
//! not inside a neighbouring piece: the leaf's own frustum and end spheres, and the frusta
//! of the leaves before and after it (across segment joints too). Without that, a ray
//! starting inside the strand (a spawned ray leaving it inwards, a camera in the hair) hits
//! the interior half of a joint sphere or a round end.

use glam::Vec4;
use raylab_core::{gamma, Frame, Ray, Vec3};

/// Leaves' chords stay within this fraction of the (smallest) radius of the curve.
const FLATNESS: f32 = 0.02;
const MAX_DEPTH: u32 = 10;

/// A hit: distance, curve parameter `u` of the segment, and `v` across the strand as the
/// ray sees it (0 and 1 at its silhouette edges, 0.5 on its axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

/// How many times to halve the cubic `cp` (positions `xyz`, radii `w`) so that each piece
/// is flat to `FLATNESS` times its radius: a cubic lies within `¾·max|Δ²p|` of its chord
/// and each halving divides the second differences by 4.
pub fn subdivision_depth(cp: &[Vec4; 4]) -> u32 {
    let l0 = (0..2).map(|i| (cp[i] - 2.0 * cp[i + 1] + cp[i + 2]).length()).fold(0.0f32, f32::max);
    let r_max = cp.iter().fold(0.0f32, |m, p| m.max(p.w));
    let r_min = cp.iter().fold(f32::INFINITY, |m, p| m.min(p.w));
    // Tapering to a point would ask for infinite depth; a twentieth of the root will do.
    let eps = FLATNESS * r_min.max(0.05 * r_max);
    if l0 == 0.0 {
        return 0;
    }
    // A zero radius makes the ratio infinite: the deepest level.
    let depth = ((0.75 * l0 / eps).log2() / 2.0).ceil();
    depth.clamp(0.0, MAX_DEPTH as f32) as u32
}

/// A cubic and its subdivision depth, as `intersect` takes them.
pub type Cubic<'a> = (&'a [Vec4; 4], u32);

/// The closest hit of `ray` with the tube of the cubic `cp` in `(t_min, t_max]`.
/// `neighbours` are the segments before and after it on the strand (`None` at its ends),
/// whose first and last leaves decide what of this segment's end pieces is interior.
pub fn intersect(cp: &[Vec4; 4], depth: u32, neighbours: [Option<Cubic>; 2], ray: &Ray) -> Option<CurveHit> {
    let len = ray.dir.length();
    let frame = Frame::from_z(ray.dir / len);
    let local = cp.map(|p| frame.to_local(p.truncate() - ray.origin).extend(p.w));
    let mut search = Search { len, t_min: ray.t_min, t_max: ray.t_max, best: None, root: local, frame, origin: ray.origin, neighbours };
    search.recurse(&local, 0.0, 1.0, depth);
    search.best
}

struct Search<'a> {
    /// `|dir|`: ray-space z is `t·len`.
    len: f32,
    t_min: f32,
    /// The closest hit so far, or the ray's end.
    t_max: f32,
    best: Option<CurveHit>,
    /// The whole cubic in ray space, the ray's frame, and the neighbouring segments in
    /// world space: where the leaves next to a leaf come from.
    root: [Vec4; 4],
    frame: Frame,
    origin: Vec3,
    neighbours: [Option<Cubic<'a>>; 2],
}

/// A leaf in coordinates shifted to its middle: chord ends `a`, `b` (radius in `w`), the
/// far ends of the leaves before and after it (`None` at the strand's ends), and `delta`,
/// the depth below which a point counts as on a piece's surface rather than inside it.
struct Leaf {
    a: Vec4,
    b: Vec4,
    before: Option<Vec4>,
    after: Option<Vec4>,
    delta: f32,
}

impl Leaf {
    /// Whether `p` is inside the tube by more than `delta`, judged on the pieces other than `own` that can
    /// reach it: the end spheres, this frustum, the neighbours' frusta and far-end spheres (those reach back).
    fn interior(&self, p: Vec3, own: Piece) -> bool {
        let d = self.delta;
        (own != Piece::SphereA && in_sphere(p, self.a, d))
            || (own != Piece::SphereB && in_sphere(p, self.b, d))
            || (own != Piece::Frustum && in_frustum(p, self.a, self.b, d))
            || self.before.is_some_and(|e| in_frustum(p, self.a, e, d) || in_sphere(p, e, d))
            || self.after.is_some_and(|e| in_frustum(p, self.b, e, d) || in_sphere(p, e, d))
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Piece {
    SphereA,
    SphereB,
    Frustum,
}

fn in_sphere(p: Vec3, c: Vec4, delta: f32) -> bool {
    (p - c.truncate()).length() < c.w - delta
}

/// Whether `p` is more than `delta` inside the solid frustum from `j` to `e` (radii in
/// `w`) radially, within its length grown by `delta` at both ends. The growth keeps points
/// on a joint's plane inside one of the two frusta that meet there whatever the rounding of
/// the two axial coordinates; the grown slab is inside the end spheres, so nothing on the
/// tube's true boundary is taken for interior.
fn in_frustum(p: Vec3, j: Vec4, e: Vec4, delta: f32) -> bool {
    let axis = (e - j).truncate();
    let l = axis.length();
    if l == 0.0 {
        return false;
    }
    let dir = axis / l;
    let q = p - j.truncate();
    let h = q.dot(dir);
    if !(-delta..=l + delta).contains(&h) {
        return false;
    }
    let k = (e.w - j.w) / l;
    // Distance to the cone's side, measured at right angles to it.
    (j.w + k * h - (q - h * dir).length()) / (1.0 + k * k).sqrt() > delta
}

impl Search<'_> {
    fn recurse(&mut self, cp: &[Vec4; 4], u0: f32, u1: f32, depth: u32) {
        let r = cp.iter().fold(0.0f32, |m, p| m.max(p.w));
        let lo = cp.iter().fold(Vec3::INFINITY, |m, p| m.min(p.truncate())) - Vec3::splat(r);
        let hi = cp.iter().fold(Vec3::NEG_INFINITY, |m, p| m.max(p.truncate())) + Vec3::splat(r);
        if lo.x > 0.0 || hi.x < 0.0 || lo.y > 0.0 || hi.y < 0.0 {
            return;
        }
        // The z test prunes with slack: a grazing root can land a little outside the hull,
        // and a pruned hit must never be one the ray's interval allows (structures pass
        // different `t_max` and must all find the same hit).
        let slack = 0.01 * r + 1e-5 * lo.z.abs().max(hi.z.abs());
        if hi.z + slack < self.t_min * self.len || lo.z - slack > self.t_max * self.len {
            return;
        }
        if depth == 0 {
            return self.leaf(cp, u0, u1);
        }
        let (a, b) = halves(cp);
        let um = 0.5 * (u0 + u1);
        // Nearer half first, so that its hit shrinks the interval for the other.
        if a[0].z.min(a[3].z) <= b[0].z.min(b[3].z) {
            self.recurse(&a, u0, um, depth - 1);
            self.recurse(&b, um, u1, depth - 1);
        } else {
            self.recurse(&b, um, u1, depth - 1);
            self.recurse(&a, u0, um, depth - 1);
        }
    }

    /// The frustum along the chord and the spheres at its ends. Coordinates are shifted
    /// along z to the leaf's middle, so that the quadratics see small, well-conditioned
    /// numbers whatever the distance to the ray's origin; `s` is the ray's z from there.
    fn leaf(&mut self, cp: &[Vec4; 4], u0: f32, u1: f32) {
        let zc = 0.5 * (cp[0].z + cp[3].z);
        let shift = Vec4::new(0.0, 0.0, zc, 0.0);
        let (before, after) = (self.beyond(u0, u0 - u1).map(|p| p - shift), self.beyond(u1, u1 - u0).map(|p| p - shift));
        let size = cp[0].truncate().abs().max(cp[3].truncate().abs()).max_element() + cp[0].w.max(cp[3].w);
        // The hit point and the pieces' ends carry the rounding of the ray-space transform
        // (a few ulps of the distances from the ray's origin, at most `size`) and of the
        // roots and neighbours' evaluation (a few ulps of the leaf's size): γ₃₂ of `size`
        // bounds both. A spawned ray starts at least γ₆₄·(|o| + t|d| + |p|) + 10⁻⁴ r inside
        // (`Curve::surface`), so the interior crossings it meets are deeper than this.
        let delta = gamma(32) * size;
        let leaf = Leaf { a: cp[0] - shift, b: cp[3] - shift, before, after, delta };
        let axis = (leaf.b - leaf.a).truncate();
        self.sphere(&leaf, Piece::SphereA, axis, zc, u0);
        // The sphere at `b` is the next leaf's first, and lies in that leaf's box: only
        // the segment's last one needs testing here.
        if u1 == 1.0 {
            self.sphere(&leaf, Piece::SphereB, axis, zc, u1);
        }
        self.frustum(&leaf, zc, u0, u1);
    }

    /// The far end (ray space, unshifted) of the leaf of width `|du|` beyond the leaf end
    /// at `u` (before it for negative `du`): from this cubic, or across the joint from the
    /// neighbouring segment's last or first leaf; `None` past the strand's ends.
    fn beyond(&self, u: f32, du: f32) -> Option<Vec4> {
        let w = u + du;
        if (0.0..=1.0).contains(&w) {
            return Some(eval(&self.root, w));
        }
        let (cp, depth) = self.neighbours[usize::from(w > 1.0)]?;
        let step = 0.5f32.powi(depth as i32);
        let p = eval(cp, if w > 1.0 { step } else { 1.0 - step });
        Some(self.frame.to_local(p.truncate() - self.origin).extend(p.w))
    }

    fn accept(&mut self, s: f32, zc: f32, u: f32, v: f32) -> bool {
        let t = (zc + s) / self.len;
        let ok = t > self.t_min && t <= self.t_max;
        if ok {
            self.t_max = t;
            self.best = Some(CurveHit { t, u, v });
        }
        ok
    }

    fn sphere(&mut self, leaf: &Leaf, piece: Piece, axis: Vec3, zc: f32, u: f32) {
        let c = if piece == Piece::SphereA { leaf.a } else { leaf.b };
        let (r, c) = (c.w, c.truncate());
        let d2 = c.x * c.x + c.y * c.y;
        if d2 > r * r {
            return;
        }
        let h = (r * r - d2).sqrt();
        let v = across(axis, c, r);
        for s in [c.z - h, c.z + h] {
            if !leaf.interior(Vec3::new(0.0, 0.0, s), piece) && self.accept(s, zc, u, v) {
                return;
            }
        }
    }

    /// The side of the cone frustum from `a` (radius `ra`) to `b` (radius `rb`), hit by the
    /// z axis: `|x⊥|² = r(h)²`, `h` the axial coordinate, is a quadratic in `s`.
    fn frustum(&mut self, leaf: &Leaf, zc: f32, u0: f32, u1: f32) {
        let (a, b, ra, rb) = (leaf.a.truncate(), leaf.b.truncate(), leaf.a.w, leaf.b.w);
        let axis = b - a;
        let l = axis.length();
        if l == 0.0 {
            return;
        }
        let dir = axis / l;
        let k = (rb - ra) / l;
        let h0 = -a.dot(dir);
        let perp = -a - h0 * dir;
        let r0 = ra + k * h0;
        let dz = dir.z;
        let qa = dir.x * dir.x + dir.y * dir.y - dz * dz * k * k; // 1 − dz²(1 + k²), without 1 − dz²'s cancellation
        let qb = 2.0 * (perp.z - r0 * k * dz);
        let qc = perp.length_squared() - r0 * r0;
        if qa == 0.0 {
            return; // along the axis (or a cone's side): the end spheres are what the ray sees
        }
        let disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            return;
        }
        // Stable roots: `q` has the sign of `-qb`, so no cancellation.
        let q = -0.5 * (qb + disc.sqrt().copysign(qb));
        let (mut s0, mut s1) = (q / qa, if q != 0.0 { qc / q } else { q / qa });
        if s0 > s1 {
            std::mem::swap(&mut s0, &mut s1);
        }
        for s in [s0, s1] {
            let h = h0 + s * dz;
            let r = ra + k * h;
            if (0.0..=l).contains(&h) && r >= 0.0 && !leaf.interior(Vec3::new(0.0, 0.0, s), Piece::Frustum) {
                let v = across(axis, a + h * dir - Vec3::new(0.0, 0.0, s), r);
                if self.accept(s, zc, u0 + (u1 - u0) * (h / l), v) {
                    return;
                }
            }
        }
    }
}

/// The cubic `p` at `u` (de Casteljau), position and radius.
fn eval(p: &[Vec4; 4], u: f32) -> Vec4 {
    let (a, b, c) = (p[0].lerp(p[1], u), p[1].lerp(p[2], u), p[2].lerp(p[3], u));
    let (d, e) = (a.lerp(b, u), b.lerp(c, u));
    d.lerp(e, u)
}

/// `v` of a hit whose axis point is `c` (relative to the ray's point at that depth): the
/// ray's offset from the axis across the strand's projection, from 0 to 1.
fn across(axis: Vec3, c: Vec3, r: f32) -> f32 {
    let side = glam::Vec2::new(axis.x, axis.y);
    let len = side.length();
    if len == 0.0 || r <= 0.0 {
        return 0.5;
    }
    let offset = (side.x * c.y - side.y * c.x) / (len * r);
    0.5 + 0.5 * offset.clamp(-1.0, 1.0)
}

/// The cubic's two halves at `u = 1/2`.
fn halves(p: &[Vec4; 4]) -> ([Vec4; 4], [Vec4; 4]) {
    let p01 = 0.5 * (p[0] + p[1]);
    let p12 = 0.5 * (p[1] + p[2]);
    let p23 = 0.5 * (p[2] + p[3]);
    let p012 = 0.5 * (p01 + p12);
    let p123 = 0.5 * (p12 + p23);
    let mid = 0.5 * (p012 + p123);
    ([p[0], p01, p012, mid], [mid, p123, p23, p[3]])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn straight(r0: f32, r1: f32) -> [Vec4; 4] {
        [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0].map(|s| Vec4::new(2.0 * s - 1.0, 0.0, 0.0, r0 + (r1 - r0) * s))
    }

    #[test]
    fn straight_cylinder_hand_computed() {
        let cp = straight(0.25, 0.25);
        assert_eq!(subdivision_depth(&cp), 0);
        // Down the y axis onto the cylinder of radius 1/4 along x: t = 2 - 0.25.
        let hit = intersect(&cp, 0, [None, None], &Ray::new(Vec3::new(0.5, 2.0, 0.0), -Vec3::Y)).unwrap();
        assert!((hit.t - 1.75).abs() < 1e-6, "{hit:?}");
        assert!((hit.u - 0.75).abs() < 1e-6 && (hit.v - 0.5).abs() < 1e-6, "{hit:?}");
        // Off the axis by r/2 in z: the chord through the circle, t = 2 - √(r² - (r/2)²).
        let hit = intersect(&cp, 0, [None, None], &Ray::new(Vec3::new(0.0, 2.0, 0.125), -Vec3::Y)).unwrap();
        assert!((hit.t - (2.0 - (0.0625f32 - 0.015625).sqrt())).abs() < 1e-6, "{hit:?}");
        assert!((hit.v - 0.5).abs() > 0.2, "{hit:?}");
        // A ray past the end of the tube by less than a radius hits the round end.
        let hit = intersect(&cp, 0, [None, None], &Ray::new(Vec3::new(1.1, 2.0, 0.0), -Vec3::Y)).unwrap();
        assert!((hit.t - (2.0 - (0.0625f32 - 0.01).sqrt())).abs() < 1e-5 && hit.u == 1.0, "{hit:?}");
        // Misses beside the tube and beyond the ray's interval.
        assert!(intersect(&cp, 0, [None, None], &Ray::new(Vec3::new(0.0, 2.0, 0.3), -Vec3::Y)).is_none());
        assert!(intersect(&cp, 0, [None, None], &Ray::segment(Vec3::new(0.5, 2.0, 0.0), -Vec3::Y, 0.0, 1.7)).is_none());
        // From inside, the exit.
        let hit = intersect(&cp, 0, [None, None], &Ray::new(Vec3::ZERO, Vec3::Y)).unwrap();
        assert!((hit.t - 0.25).abs() < 1e-6);
    }

    #[test]
    fn from_inside_only_the_tube_is_hit_not_its_interior_pieces() {
        let cp = straight(0.25, 0.25);
        // Along the axis from the middle: the round end's far side at x = 1.25, not the
        // sphere's near half (x = 0.75), which is inside the cylinder.
        let hit = intersect(&cp, 0, [None, None], &Ray::new(Vec3::ZERO, Vec3::X)).unwrap();
        // Looking down the axis the strand has no width: v is ½.
        assert!((hit.t - 1.25).abs() < 1e-6 && hit.u == 1.0 && hit.v == 0.5, "{hit:?}");
        // With a next segment from x = 1 to 3, the joint sphere is all interior: this
        // segment has nothing to report, the next one reports its end at 3.25.
        let next = straight(0.25, 0.25).map(|p| p + Vec4::new(2.0, 0.0, 0.0, 0.0));
        let ray = Ray::new(Vec3::new(0.9, 0.0, 0.01), Vec3::X);
        assert_eq!(intersect(&cp, 0, [None, Some((&next, 0))], &ray), None);
        let hit = intersect(&next, 0, [Some((&cp, 0)), None], &ray).unwrap();
        assert!((hit.t - (2.1 + (0.0625f32 - 0.0001).sqrt())).abs() < 1e-5 && hit.u == 1.0, "{hit:?}");
        // Across the joint from outside, the tube's side is still hit (at x = 1 exactly,
        // where the frusta and the joint sphere meet).
        let hit = intersect(&cp, 0, [None, Some((&next, 0))], &Ray::new(Vec3::new(1.0, 2.0, 0.0), -Vec3::Y)).unwrap();
        assert!((hit.t - 1.75).abs() < 1e-6, "{hit:?}");
    }

    #[test]
    fn tapered_frustum_hand_computed() {
        // Radius 0.5 at x = -1 to 0 at x = 1: 0.25 at x = 0.
        let cp = straight(0.5, 0.0);
        let hit = intersect(&cp, subdivision_depth(&cp), [None, None], &Ray::new(Vec3::new(0.0, 3.0, 0.0), -Vec3::Y)).unwrap();
        assert!((hit.t - 2.75).abs() < 1e-5, "{hit:?}");
        // Along the axis from beyond the tip: the tip is a point, the wide end a sphere.
        let hit = intersect(&cp, subdivision_depth(&cp), [None, None], &Ray::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::X)).unwrap();
        assert!((hit.t - 1.5).abs() < 1e-5, "{hit:?}");
    }

    #[test]
    fn depth_follows_curvature_and_radius() {
        let bent = [Vec4::new(0.0, 0.0, 0.0, 0.01), Vec4::new(0.0, 1.0, 0.0, 0.01), Vec4::new(1.0, 1.0, 0.0, 0.01), Vec4::new(1.0, 0.0, 0.0, 0.01)];
        // max|Δ²p| = √2 → ¾·√2 / (0.02·0.01) ≈ 5303 → ⌈log₄ 5303⌉ = 7.
        assert_eq!(subdivision_depth(&bent), 7);
        // A radius 100 times larger: ⌈log₄ 53.03⌉ = 3.
        let thick = bent.map(|p| Vec4::new(p.x, p.y, p.z, 1.0));
        assert_eq!(subdivision_depth(&thick), 3);
    }

    /// A straight tube of radius ¼ along x, 1000 away (from y = 1000.25 down, top y = ¼ at
    /// t = 1000, bottom at 1000.5): as exact as near by, which the shift of each leaf to its
    /// middle depth buys (unshifted, |perp|² ≈ 10⁶ would round away r² = 1/16). The z cull's
    /// slack there is 0.01r + 10⁻⁵·1000.5 ≈ 0.0125: a hull face 0.002 inside the ray's
    /// interval must not be pruned, at either end of it.
    #[test]
    fn far_tube_is_hit_as_exactly_as_a_near_one() {
        let cp = straight(0.25, 0.25);
        let o = Vec3::new(0.5, 1000.25, 0.0);
        let hit = intersect(&cp, 0, [None, None], &Ray::new(o, -Vec3::Y)).unwrap();
        assert!((hit.t - 1000.0).abs() < 2e-4 && (hit.u - 0.75).abs() < 1e-6, "{hit:?}");
        // Off the axis by r/2: t = 1000.25 - √(r² - r²/4).
        let hit = intersect(&cp, 0, [None, None], &Ray::new(o + Vec3::new(0.0, 0.0, 0.125), -Vec3::Y)).unwrap();
        assert!((f64::from(hit.t) - (1000.25 - (0.0625f64 - 0.015625).sqrt())).abs() < 2e-4, "{hit:?}");
        // The top found with t_max 0.002 beyond it, the bottom with t_min 0.002 before it.
        let hit = intersect(&cp, 0, [None, None], &Ray::segment(o, -Vec3::Y, 0.0, 1000.002)).unwrap();
        assert!((hit.t - 1000.0).abs() < 2e-4, "{hit:?}");
        let hit = intersect(&cp, 0, [None, None], &Ray::segment(o, -Vec3::Y, 1000.498, f32::INFINITY)).unwrap();
        assert!((hit.t - 1000.5).abs() < 2e-4, "{hit:?}");
    }

    /// The ray's interval in ray space is `t·|dir|`: the tube of radius ¼ along x from y = 2
    /// (top at distance 1.75, bottom 2.25) with directions of length ½ and 2.
    #[test]
    fn the_interval_scales_with_the_direction() {
        let cp = straight(0.25, 0.25);
        let o = Vec3::new(0.5, 2.0, 0.0);
        // t_min ½ (distance ½): the top.
        let hit = intersect(&cp, 0, [None, None], &Ray::segment(o, -Vec3::Y, 0.5, f32::INFINITY)).unwrap();
        assert!((hit.t - 1.75).abs() < 1e-6, "{hit:?}");
        // t_min 2.249 (distance 2.249): the bottom, 0.001 beyond it.
        let hit = intersect(&cp, 0, [None, None], &Ray::segment(o, -Vec3::Y, 2.249, f32::INFINITY)).unwrap();
        assert!((hit.t - 2.25).abs() < 1e-6, "{hit:?}");
        // |dir| = ½, t_min 3 (distance 1.5): the top at t = 3.5.
        let hit = intersect(&cp, 0, [None, None], &Ray::segment(o, Vec3::new(0.0, -0.5, 0.0), 3.0, f32::INFINITY)).unwrap();
        assert!((hit.t - 3.5).abs() < 1e-5, "{hit:?}");
        // |dir| = 2 from y = 5.75, t_max 3 (distance 6): the top at distance 5.5, t = 2.75.
        let hit = intersect(&cp, 0, [None, None], &Ray::segment(Vec3::new(0.5, 5.75, 0.0), Vec3::new(0.0, -2.0, 0.0), 0.0, 3.0)).unwrap();
        assert!((hit.t - 2.75).abs() < 1e-5, "{hit:?}");
    }

    /// The interval is open at `t_min`: a ray leaving the top of the tube from exactly on it
    /// (all exact in f32: the roots are t = 0 and -½) hits nothing.
    #[test]
    fn a_ray_from_the_surface_does_not_hit_it_at_t_min() {
        let cp = straight(0.25, 0.25);
        assert_eq!(intersect(&cp, 0, [None, None], &Ray::new(Vec3::new(0.5, 0.25, 0.0), Vec3::Y)), None);
        // Inwards, the far side: t = ½.
        let hit = intersect(&cp, 0, [None, None], &Ray::new(Vec3::new(0.5, 0.25, 0.0), -Vec3::Y)).unwrap();
        assert!((hit.t - 0.5).abs() < 1e-6, "{hit:?}");
    }

    /// The raised bent strand of `curve::tests` (z = u², r = 0.05), whose second half is the
    /// nearer from above at every level: straight down onto its two round ends p(1) = (2, 0, 1)
    /// (t = 3 - 1.05) and p(0) = (0, 0, 0) (t ≈ 3 - 0.05; the first leaf's chord rises by
    /// less than 10⁻³r there). The recursion must end at every one of its levels, whichever
    /// half it searches first.
    #[test]
    fn round_ends_of_a_bent_strand_searched_nearer_half_first() {
        let third = 1.0 / 3.0;
        let cp = [Vec4::new(0.0, 0.0, 0.0, 0.05), Vec4::new(2.0 * third, 4.0 * third, 0.0, 0.05), Vec4::new(4.0 * third, 4.0 * third, third, 0.05), Vec4::new(2.0, 0.0, 1.0, 0.05)];
        let depth = subdivision_depth(&cp);
        assert!(depth > 2, "{depth}");
        let hit = intersect(&cp, depth, [None, None], &Ray::new(Vec3::new(2.0, 0.0, 3.0), -Vec3::Z)).unwrap();
        assert!((hit.t - 1.95).abs() < 1e-5 && hit.u == 1.0, "{hit:?}");
        let hit = intersect(&cp, depth, [None, None], &Ray::new(Vec3::new(0.0, 0.0, 3.0), -Vec3::Z)).unwrap();
        assert!((hit.t - 2.95).abs() < 1e-4 && hit.u < 1e-2, "{hit:?}");
    }

    /// v = ½ + δ/(2r), δ the ray's offset from the axis along n × axis (n towards the viewer),
    /// the direction of `Curve::surface`'s ∂p/∂v = n × axis · 2r. A tube of radius ¼ from
    /// (-1, -1, 0) to (1, 1, 0) seen from above (n = ẑ, n × axis = (-1, 1, 0)/√2), at u = 0.6
    /// (the point (0.2, 0.2, 0)), δ = ±r/2: v = ¾ and ¼, t = 3 - √(r² - δ²).
    #[test]
    fn v_runs_across_the_strand_along_dpdv() {
        let cp = [-1.0f32, -1.0 / 3.0, 1.0 / 3.0, 1.0].map(|s| Vec4::new(s, s, 0.0, 0.25));
        let across = Vec3::new(-1.0, 1.0, 0.0) / 2f32.sqrt();
        for (delta, v) in [(0.125f32, 0.75f32), (-0.125, 0.25)] {
            let o = Vec3::new(0.2, 0.2, 3.0) + delta * across;
            let hit = intersect(&cp, 0, [None, None], &Ray::new(o, -Vec3::Z)).unwrap();
            let t = 3.0 - (0.0625f64 - 0.015625).sqrt();
            assert!((f64::from(hit.t) - t).abs() < 1e-5 && (hit.u - 0.6).abs() < 1e-5 && (hit.v - v).abs() < 1e-5, "{delta}: {hit:?}");
        }
        // The round end: straight(¼) seen down -y past x = 1 (sphere centre (1, 0, 0)), the ray
        // at x = 1.1, z = 0.1: n ≈ ŷ, n × x̂ = -ẑ, so δ = -0.1 and v = ½ - 0.1/(2r) = 0.3;
        // t = 2 - √(r² - 0.1² - 0.1²), u = 1.
        let hit = intersect(&straight(0.25, 0.25), 0, [None, None], &Ray::new(Vec3::new(1.1, 2.0, 0.1), -Vec3::Y)).unwrap();
        assert!((f64::from(hit.t) - (2.0 - 0.0425f64.sqrt())).abs() < 1e-5 && hit.u == 1.0 && (hit.v - 0.3).abs() < 1e-5, "{hit:?}");
        // A tapered tube, r(x) = 0.3 - 0.2x: at x = ½, r = 0.2; the ray at z = 0.1 (δ = -0.1):
        // v = ½ - 0.1/0.4 = ¼, t = 2 - √(0.2² - 0.1²), u = ¾.
        let hit = intersect(&straight(0.5, 0.1), 0, [None, None], &Ray::new(Vec3::new(0.5, 2.0, 0.1), -Vec3::Y)).unwrap();
        assert!((f64::from(hit.t) - (2.0 - 0.03f64.sqrt())).abs() < 1e-5 && (hit.u - 0.75).abs() < 1e-5 && (hit.v - 0.25).abs() < 1e-5, "{hit:?}");
    }

    /// The nearest root t > 0 of the ray o + t·d with the cone about the x axis of radius
    /// r(x) = r0 + k(x + 1) (y² + z² = r(x)²), in f64, and the hit's x.
    fn cone_about_x(o: [f64; 3], d: [f64; 3], r0: f64, k: f64) -> (f64, f64) {
        let (rc, rd) = (r0 + k * (o[0] + 1.0), k * d[0]);
        let a = d[1] * d[1] + d[2] * d[2] - rd * rd;
        let b = 2.0 * (o[1] * d[1] + o[2] * d[2] - rc * rd);
        let c = o[1] * o[1] + o[2] * o[2] - rc * rc;
        let t = (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
        (t, o[0] + t * d[0])
    }

    /// Oblique rays (not at right angles to the axis, directions not of unit length) onto a
    /// straight and a tapered tube, against the closed form of the ray–cone intersection.
    #[test]
    fn oblique_rays_match_the_closed_form_cone() {
        for (r0, r1, o, d) in [
            (0.25, 0.25, [0.3, 2.0, 0.8], [0.1, -1.0, -0.4]),
            (0.25, 0.25, [0.3, 2.0, 0.9], [0.1, -1.0, -0.4]),
            (0.5, 0.1, [0.2, 2.0, 0.5], [-0.3, -1.0, -0.2]),
            (0.5, 0.1, [-0.5, 1.5, -1.0], [0.4, -0.6, 0.5]),
            (0.1, 0.4, [0.6, -1.0, 2.0], [-0.2, 0.5, -1.0]),
        ] {
            let (t, x) = cone_about_x(o, d, r0, (r1 - r0) / 2.0);
            assert!(t > 0.0 && x.abs() < 0.9, "{t} {x}");
            let ray = Ray::new(Vec3::from(o.map(|c| c as f32)), Vec3::from(d.map(|c| c as f32)));
            let hit = intersect(&straight(r0 as f32, r1 as f32), 0, [None, None], &ray).unwrap();
            assert!((f64::from(hit.t) - t).abs() < 1e-5 && (f64::from(hit.u) - (x + 1.0) / 2.0).abs() < 1e-5, "{r0} {r1} {o:?}: {hit:?} vs {t} at x = {x}");
        }
    }

    /// From inside near the wall, at a few 10⁻⁴ rad to the axis: the tube of radius ¼ along x
    /// from −1 to 1, the ray from (−0.5, 0.2499, 0) along (1, d, 0) leaves through the side
    /// y = ¼ at t = 10⁻⁴/d (|(1, d, 0)| = 1 + O(d²)), x = −0.5 + t, u = (x + 1)/2. With
    /// `qa` computed as 1 − dz², mostly rounding there, these exits were not found at all.
    #[test]
    fn grazing_exit_from_inside_near_the_wall() {
        for d in [1e-4f32, 2e-4, 3e-4, 5e-4, 1e-3] {
            let hit = intersect(&straight(0.25, 0.25), 0, [None, None], &Ray::new(Vec3::new(-0.5, 0.2499, 0.0), Vec3::new(1.0, d, 0.0))).unwrap();
            let t = 1e-4 / f64::from(d);
            assert!((f64::from(hit.t) - t).abs() < 1e-2 * t, "d {d}: {hit:?}, t {t}");
            assert!((f64::from(hit.u) - (0.5 + t) / 2.0).abs() < 1e-2, "d {d}: {hit:?}");
        }
    }

    /// A round end wider than 2: the ray along the axis of a tube of radius 4, 3.5 off it,
    /// meets the end sphere at x = -1 - √(16 - 3.5²) (d² = 12.25 < r² but more than 2r).
    #[test]
    fn a_fat_round_end() {
        let hit = intersect(&straight(4.0, 4.0), 0, [None, None], &Ray::new(Vec3::new(-10.0, 3.5, 0.0), Vec3::X)).unwrap();
        assert!((f64::from(hit.t) - (9.0 - 3.75f64.sqrt())).abs() < 1e-5 && hit.u == 0.0 && hit.v == 0.5, "{hit:?}");
    }

    /// The joint test of `from_inside_only_the_tube_is_hit_not_its_interior_pieces` at a
    /// thousandth of the size (radius 2.5·10⁻⁴): the interior tolerance scales with the leaf.
    #[test]
    fn from_inside_a_thin_strand() {
        let cp = straight(0.25, 0.25).map(|p| p * 1e-3);
        let next = cp.map(|p| p + Vec4::new(2e-3, 0.0, 0.0, 0.0));
        let ray = Ray::new(Vec3::new(0.9e-3, 0.0, 1e-5), Vec3::X);
        assert_eq!(intersect(&cp, 0, [None, Some((&next, 0))], &ray), None);
        let hit = intersect(&next, 0, [Some((&cp, 0)), None], &ray).unwrap();
        assert!((f64::from(hit.t) - 1e-3 * (2.1 + 0.0624f64.sqrt())).abs() < 1e-8 && hit.u == 1.0, "{hit:?}");
    }

    /// A leaf shorter than its diameter (x from -0.1 to 0.1, radius ¼): its end spheres
    /// overlap, and from the middle along ±x each sphere's near side is inside the other.
    /// The exits are the far sides, x = ±0.35.
    #[test]
    fn overlapping_end_spheres_from_inside() {
        let cp = [-0.1f32, -0.1 / 3.0, 0.1 / 3.0, 0.1].map(|x| Vec4::new(x, 0.0, 0.0, 0.25));
        for (dir, u) in [(Vec3::X, 1.0), (-Vec3::X, 0.0)] {
            let hit = intersect(&cp, 0, [None, None], &Ray::new(Vec3::ZERO, dir)).unwrap();
            assert!((hit.t - 0.35).abs() < 1e-6 && hit.u == u, "{dir}: {hit:?}");
        }
    }

    fn bernstein(cp: &[Vec4; 4], u: f64) -> glam::DVec4 {
        let s = 1.0 - u;
        cp[0].as_dvec4() * (s * s * s) + cp[1].as_dvec4() * (3.0 * s * s * u) + cp[2].as_dvec4() * (3.0 * s * u * u) + cp[3].as_dvec4() * (u * u * u)
    }

    /// The cubic's leaves' ends at `depth`, (position, radius) in f64.
    fn nodes(cp: &[Vec4; 4], depth: u32) -> Vec<glam::DVec4> {
        let n = 1u32 << depth;
        (0..=n).map(|i| bernstein(cp, f64::from(i) / f64::from(n))).collect()
    }

    /// Whether `p` is inside the union of the round cones between consecutive nodes and the
    /// spheres at the nodes: the tube as the module describes it, in f64.
    fn in_union(nodes: &[glam::DVec4], p: glam::DVec3) -> bool {
        nodes.iter().any(|c| (p - c.truncate()).length() < c.w)
            || nodes.windows(2).any(|w| {
                let (a, e) = (w[0].truncate(), w[1].truncate());
                let l = (e - a).length();
                let h = (p - a).dot(e - a) / l;
                (0.0..=l).contains(&h) && (p - a - (e - a) * (h / l)).length() < w[0].w + (w[1].w - w[0].w) * h / l
            })
    }

    /// The first t > 0 where `o + t·d` enters or leaves the union: steps of 2·10⁻⁴, then
    /// bisection.
    fn crossing(nodes: &[glam::DVec4], o: glam::DVec3, d: glam::DVec3) -> Option<f64> {
        let start = in_union(nodes, o);
        let step = 2e-4 / d.length();
        let mut t = 0.0;
        while t * d.length() < 8.0 {
            if in_union(nodes, o + (t + step) * d) != start {
                let (mut lo, mut hi) = (t, t + step);
                for _ in 0..50 {
                    let m = 0.5 * (lo + hi);
                    if in_union(nodes, o + m * d) == start { lo = m } else { hi = m }
                }
                return Some(hi);
            }
            t += step;
        }
        None
    }

    /// Strands whose leaves meet at a sharp angle or taper steeply (a V cut into 2 and 4
    /// leaves, two segments meeting at 53°, a short leaf with overlapping end spheres, a
    /// cone from radius 0.6 to 0.1 over 0.8, a radius tripling over 0.1): rays from inside, near each leaf's ends and
    /// middle, and from outside, against the first crossing of the union of the pieces
    /// computed by marching in f64. From inside that is the tube's surface, never a piece
    /// inside another (a frustum's side within the next one at the inner side of a bend, a
    /// sphere within a frustum or a sphere).
    #[test]
    fn hits_are_the_first_crossings_of_the_union_of_the_pieces() {
        let v = |r: f32| [Vec4::new(-1.0, 0.0, 0.0, r), Vec4::new(0.0, 4.0 / 3.0, 0.0, r), Vec4::new(0.0, 4.0 / 3.0, 0.0, r), Vec4::new(1.0, 0.0, 0.0, r)];
        let line = |a: Vec4, b: Vec4| [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0].map(|s| a.lerp(b, s));
        // Each strand: its segments (cubic, depth).
        let strands: Vec<Vec<([Vec4; 4], u32)>> = vec![
            vec![(v(0.25), 1)],
            vec![(v(0.15), 2)],
            vec![(line(Vec4::new(-1.0, 0.0, 0.0, 0.3), Vec4::new(0.0, 0.0, 0.0, 0.2)), 0), (line(Vec4::new(0.0, 0.0, 0.0, 0.2), Vec4::new(0.6, 0.8, 0.0, 0.1)), 0)],
            vec![(line(Vec4::new(-0.1, 0.0, 0.0, 0.25), Vec4::new(0.1, 0.0, 0.0, 0.25)), 0)],
            vec![(line(Vec4::new(-0.4, 0.0, 0.0, 0.6), Vec4::new(0.4, 0.0, 0.0, 0.1)), 0)],
            vec![(line(Vec4::new(-1.0, 0.0, 0.0, 0.1), Vec4::new(0.0, 0.0, 0.0, 0.1)), 0), (line(Vec4::new(0.0, 0.0, 0.0, 0.1), Vec4::new(0.1, 0.0, 0.0, 0.3)), 0)],
        ];
        let dirs = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.3, 0.8, 0.2], [-0.7, 0.4, 0.5], [0.5, -0.6, -0.3], [-0.2, -0.9, 0.6], [0.9, 0.3, -0.4], [-0.6, -0.2, -0.8]];
        let mut checked = 0;
        for strand in &strands {
            let mut all: Vec<glam::DVec4> = Vec::new();
            for (cp, depth) in strand {
                let n = nodes(cp, *depth);
                let skip = usize::from(!all.is_empty());
                all.extend(&n[skip..]);
            }
            let hit = |ray: &Ray| {
                (0..strand.len()).filter_map(|i| {
                    let nb = |k: Option<usize>| k.and_then(|k| strand.get(k)).map(|(cp, d)| (cp, *d));
                    intersect(&strand[i].0, strand[i].1, [nb(i.checked_sub(1)), nb(Some(i + 1))], ray)
                }).map(|h| h.t).reduce(f32::min)
            };
            let mut rays = Vec::new();
            for w in all.windows(2) {
                for f in [0.1, 0.5, 0.9] {
                    let c = w[0].lerp(w[1], f);
                    // Inside: off the chord by 0.3 of the radius there.
                    let o = c.truncate() + glam::DVec3::new(0.3, -0.5, 0.8).normalize() * (0.3 * c.w);
                    for d in dirs {
                        rays.push((o, glam::DVec3::from(d)));
                    }
                    // Outside: from 2 away, aimed 0.4r beside the chord.
                    for d in &dirs[5..] {
                        let d = glam::DVec3::from(*d).normalize();
                        rays.push((c.truncate() - 2.0 * d + glam::DVec3::new(0.0, 0.0, 0.4 * c.w), d));
                    }
                }
            }
            for (o, d) in rays {
                let want = crossing(&all, o, d);
                let got = hit(&Ray::new(o.as_vec3(), d.as_vec3()));
                match (got, want) {
                    (None, None) => {}
                    (Some(t), Some(w)) => assert!((f64::from(t) - w).abs() < 1e-4, "{o} {d}: {t} vs {w}"),
                    _ => panic!("{o} {d}: {got:?} vs {want:?}"),
                }
                checked += 1;
            }
        }
        assert!(checked > 500, "{checked}");
    }

    /// From inside, the exit root when the entry behind the origin lies at the leaf's middle
    /// depth (its constant term ≈ 0): the tube of radius ¼ along x entered at P = (0.5, ¼, 0)
    /// along d = (0.5, -1, 0.3), P ⟂ d, so that P is the ray's point at the depth of the
    /// segment's middle (the origin). The exit, the larger root of
    /// (P.y + t·d.y)² + (P.z + t·d.z)² = r² (t from P), in f64.
    #[test]
    fn the_exit_from_inside_when_the_entry_is_at_the_middle_depth() {
        let (p, d) = ([0.5f64, 0.25, 0.0], [0.5f64, -1.0, 0.3]);
        let a = d[1] * d[1] + d[2] * d[2];
        let b = 2.0 * (p[1] * d[1] + p[2] * d[2]);
        let c = p[1] * p[1] + p[2] * p[2] - 0.0625;
        let t = (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
        assert!((p[0] + t * d[0]).abs() < 0.9 && c == 0.0, "{t}");
        // From P + 0.1·d, inside.
        let o = Vec3::new(0.55, 0.15, 0.03);
        let hit = intersect(&straight(0.25, 0.25), 0, [None, None], &Ray::new(o, Vec3::new(0.5, -1.0, 0.3))).unwrap();
        assert!((f64::from(hit.t) - (t - 0.1)).abs() < 1e-5, "{hit:?} vs {}", t - 0.1);
    }

    /// A V of two leaves (depth 1, chords (-1, 0, 0) to (0, 1, 0) to (1, 0, 0)) fatter than
    /// its chords are long, radius 1.2: from the apex straight down, the ray leaves both
    /// cylinders at once at their inner crease, y = 1 - 1.2·√2 (distance 1.2 from both axes
    /// y = ±x + 1, outside the spheres at (±1, 0, 0): √(1 + 0.697²) > 1.2), t = 1.2·√2. A point
    /// on both frusta is on the tube's surface, inside neither.
    #[test]
    fn a_fat_v_is_left_at_its_inner_crease() {
        let cp = [Vec4::new(-1.0, 0.0, 0.0, 1.2), Vec4::new(0.0, 4.0 / 3.0, 0.0, 1.2), Vec4::new(0.0, 4.0 / 3.0, 0.0, 1.2), Vec4::new(1.0, 0.0, 0.0, 1.2)];
        let hit = intersect(&cp, 1, [None, None], &Ray::new(Vec3::new(0.0, 1.0, 0.0), -Vec3::Y)).unwrap();
        assert!((f64::from(hit.t) - 1.2 * 2f64.sqrt()).abs() < 1e-5, "{hit:?}");
    }

    /// A radius that triples over a short segment (0.1 at x = 0 to 0.3 at x = 0.1, after a
    /// segment of radius 0.1 from x = -1): the next segment's far-end sphere (centre
    /// (0.1, 0, 0), radius 0.3) reaches back over the joint and covers the first segment's
    /// side for x > 0.1 - √0.08. From (-0.1, 0, 0) up y, the first segment's side y = 0.1 is
    /// inside it (0.2² + 0.1² < 0.3²): the ray leaves the tube through that sphere, at
    /// y = √(0.3² - 0.2²).
    #[test]
    fn a_neighbours_far_end_sphere_covers_the_joint() {
        let line = |a: Vec4, b: Vec4| [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0].map(|s| a.lerp(b, s));
        let first = line(Vec4::new(-1.0, 0.0, 0.0, 0.1), Vec4::new(0.0, 0.0, 0.0, 0.1));
        let next = line(Vec4::new(0.0, 0.0, 0.0, 0.1), Vec4::new(0.1, 0.0, 0.0, 0.3));
        let ray = Ray::new(Vec3::new(-0.1, 0.0, 0.0), Vec3::Y);
        assert_eq!(intersect(&first, 0, [None, Some((&next, 0))], &ray), None);
        let hit = intersect(&next, 0, [Some((&first, 0)), None], &ray).unwrap();
        assert!((f64::from(hit.t) - 0.05f64.sqrt()).abs() < 1e-5 && hit.u == 1.0, "{hit:?}");
    }

    /// Inside a fat strand (two segments of radius 1.5 along x, -2 to 0 and 0 to 4), along x,
    /// 0.5 off the axis from x = -0.5: the joint sphere's far side, x = √(1.5² - 0.5²) = √2,
    /// and the far-end sphere's near side, x = 4 - √2, are both exactly 1 inside the second
    /// cylinder; the ray leaves through the round end at x = 4 + √2, t = 4.5 + √2.
    #[test]
    fn inside_a_fat_strand_a_whole_unit_deep() {
        let line = |a: f32, b: f32| [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0].map(|s| Vec4::new(a + (b - a) * s, 0.0, 0.0, 1.5));
        let (first, next) = (line(-2.0, 0.0), line(0.0, 4.0));
        let ray = Ray::new(Vec3::new(-0.5, 0.5, 0.0), Vec3::X);
        assert_eq!(intersect(&first, 0, [None, Some((&next, 0))], &ray), None);
        let hit = intersect(&next, 0, [Some((&first, 0)), None], &ray).unwrap();
        assert!((f64::from(hit.t) - (4.5 + 2f64.sqrt())).abs() < 1e-5 && hit.u == 1.0, "{hit:?}");
    }
}
