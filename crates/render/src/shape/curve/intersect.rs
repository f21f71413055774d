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
    /// Whether `p` is inside the tube by more than `delta`, judged on the pieces other
    /// than `own` that can reach it: the end spheres, this frustum, the neighbours' frusta.
    fn interior(&self, p: Vec3, own: Piece) -> bool {
        let d = self.delta;
        (own != Piece::SphereA && in_sphere(p, self.a, d))
            || (own != Piece::SphereB && in_sphere(p, self.b, d))
            || (own != Piece::Frustum && in_frustum(p, self.a, self.b, d))
            || self.before.is_some_and(|e| in_frustum(p, self.a, e, d))
            || self.after.is_some_and(|e| in_frustum(p, self.b, e, d))
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
        let qa = 1.0 - dz * dz * (1.0 + k * k);
        let qb = 2.0 * (perp.z - r0 * k * dz);
        let qc = perp.length_squared() - r0 * r0;
        if qa.abs() < 1e-7 {
            return; // looking down the axis: the end spheres are what the ray sees
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
        assert!((hit.t - 1.25).abs() < 1e-6 && hit.u == 1.0, "{hit:?}");
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
}
