//! Curves for hair and fur: strands of Bézier segments with a radius per control point,
//! drawn as round tubes either by tessellation ([`tessellate`]) or by direct ray–curve
//! intersection ([`Curve`], one primitive per segment). See `docs/curves.md`.

mod bezier;
mod intersect;
mod tube;

pub use bezier::{to_bezier_segments, Basis, Bezier};
pub use intersect::CurveHit;
pub use tube::{rotation_minimising_normals, tessellate};

use glam::Vec4;
use raylab_core::{gamma, Aabb, Frame, Ray, Vec2, Vec3};

use super::SurfaceGeometry;
use crate::material::MaterialId;

/// How a curve shape becomes geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveMode {
    /// A triangle mesh (rings of `sides` vertices, `segments` rings per Bézier segment).
    Tube { segments: u32, sides: u32 },
    /// Direct intersection of each Bézier segment.
    Direct,
}

/// A strand for direct intersection: Bézier segments joined end to end, each one
/// primitive.
#[derive(Clone, Debug)]
pub struct Curve {
    pub segments: Vec<Bezier>,
    pub material: MaterialId,
    /// Per segment, the cubic the intersector works on and its subdivision depth.
    cubics: Vec<([Vec4; 4], u32)>,
}

impl Curve {
    pub fn new(segments: Vec<Bezier>, material: MaterialId) -> Self {
        let cubics = segments.iter().map(|s| {
            let cp = s.to_cubic();
            (cp, intersect::subdivision_depth(&cp))
        }).collect();
        Self { segments, material, cubics }
    }

    pub fn len(&self) -> usize {
        self.segments.len()
    }

    pub fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }

    /// Bytes of the segments and their prepared cubics.
    pub fn memory_bytes(&self) -> usize {
        self.segments.len() * std::mem::size_of::<Bezier>() + self.cubics.len() * std::mem::size_of::<([Vec4; 4], u32)>()
    }

    /// Bounds of segment `seg`'s tube, grown a little for the intersector's rounding so
    /// that no structure's box test rejects a hit the segment reports.
    pub fn segment_bounds(&self, seg: u32) -> Aabb {
        let s = &self.segments[seg as usize];
        let b = s.bounds();
        let pad = 1e-3 * s.max_radius() + gamma(16) * b.min.abs().max(b.max.abs()).max_element();
        Aabb { min: b.min - Vec3::splat(pad), max: b.max + Vec3::splat(pad) }
    }

    #[inline]
    pub fn intersect(&self, seg: u32, ray: &Ray) -> Option<CurveHit> {
        let seg = seg as usize;
        let cubic = |k: usize| self.cubics.get(k).map(|(cp, depth)| (cp, *depth));
        let (cp, depth) = &self.cubics[seg];
        intersect::intersect(cp, *depth, [seg.checked_sub(1).and_then(cubic), cubic(seg + 1)], ray)
    }

    /// Surface data at a hit of segment `seg` at distance `t`, curve parameter `u` and
    /// `v` across the strand. The normal is the hit's offset from the curve at `u`, with
    /// its component along the tangent removed (a round tube); at the strand's two ends,
    /// which are round, the whole offset. `uv.x` runs from 0 to 1 along the whole strand,
    /// and `dpdu` is the tangent `∂p/∂uv.x`.
    pub fn surface(&self, seg: u32, ray: &Ray, t: f32, u: f32, v: f32) -> SurfaceGeometry {
        let bezier = &self.segments[seg as usize];
        let p = ray.at(t);
        let c = bezier.eval(u);
        let tangent = bezier.derivative(u).truncate();
        let axis = tangent.try_normalize().or((bezier.point(1.0) - bezier.point(0.0)).try_normalize()).unwrap_or(Vec3::X);
        let mut n = p - c.truncate();
        let at_end = (seg == 0 && u == 0.0) || (seg as usize == self.segments.len() - 1 && u == 1.0);
        if !at_end {
            n -= axis * axis.dot(n);
        }
        let n = n.try_normalize().unwrap_or_else(|| Frame::from_z(axis).x);
        // `p = o + t·d` inherits the error of `t`: the ray-space transform rounds by a few
        // ulps of the distances involved, and grazing roots lose more relative to the
        // radius. Both terms are generous (the curve's own tests check that rays leaving
        // a hit do not hit it again).
        let scale = ray.origin.abs().max_element() + (t * ray.dir).abs().max_element() + p.abs().max_element();
        let p_error = Vec3::splat(gamma(64) * scale + 1e-4 * c.w);
        let count = self.segments.len() as f32;
        // `v` runs across the strand's width 2r, at right angles to the tangent.
        let dpdv = n.cross(axis) * (2.0 * c.w);
        SurfaceGeometry { p, p_error, ng: n, ns: n, uv: Vec2::new((seg as f32 + u) / count, v), dpdu: tangent * count, dpdv }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strand of two straight segments of radius ½ along x at y = z = 0: x from 0 to 1,
    /// then 1 to 2.
    fn strand() -> Curve {
        let cp = |x: f32| Vec4::new(x, 0.0, 0.0, 0.5);
        Curve::new(vec![Bezier::new(&[cp(0.0), cp(1.0)]).unwrap(), Bezier::new(&[cp(1.0), cp(2.0)]).unwrap()], MaterialId(2))
    }

    #[test]
    fn segment_boxes_and_memory() {
        let c = strand();
        assert_eq!((c.len(), c.is_empty()), (2, false));
        assert!(Curve::new(vec![], MaterialId(0)).is_empty());
        assert_eq!(c.memory_bytes(), 2 * std::mem::size_of::<Bezier>() + 2 * std::mem::size_of::<([Vec4; 4], u32)>());
        // The second segment's tube spans (0.5, -0.5, -0.5) to (2.5, 0.5, 0.5); the pad is
        // 10⁻³ of the radius plus γ₁₆ of the largest coordinate, 2.5.
        let b = c.segment_bounds(1);
        let pad = 1e-3 * 0.5 + 16.0 * f64::from(f32::EPSILON) * 0.5 * 2.5;
        for (got, want) in [(b.min, Vec3::new(0.5, -0.5, -0.5)), (b.max, Vec3::new(2.5, 0.5, 0.5))] {
            let d = (got - want).abs().as_dvec3();
            assert!((d - glam::DVec3::splat(pad)).abs().max_element() < 1e-7, "{got} vs {want} ± {pad}");
        }
        assert!(b.min.cmplt(Vec3::new(0.5, -0.5, -0.5)).all() && b.max.cmpgt(Vec3::new(2.5, 0.5, 0.5)).all());
    }

    #[test]
    fn hits_by_hand() {
        let c = strand();
        // Straight down onto x = 1.5 (u = ½ of the second segment, on the axis: v = ½): the
        // tube's top z = ½, from z = 3 at t = 2.5.
        let ray = Ray::new(Vec3::new(1.5, 0.0, 3.0), -Vec3::Z);
        assert!(c.intersect(0, &ray).is_none());
        let h = c.intersect(1, &ray).unwrap();
        assert!((h.t - 2.5).abs() < 1e-4 && (h.u - 0.5).abs() < 1e-4 && (h.v - 0.5).abs() < 1e-3, "{h:?}");
        // The same ray with a direction of length 2: half the distance.
        let h = c.intersect(1, &Ray::new(Vec3::new(1.5, 0.0, 3.0), Vec3::new(0.0, 0.0, -2.0))).unwrap();
        assert!((h.t - 1.25).abs() < 1e-4 && (h.u - 0.5).abs() < 1e-4, "{h:?}");
        // Off the axis by ±¼ of the radius ½ (y = ±0.25, hits at z = √(¼ - 1/16)): v is ½ ± ¼,
        // one on each side.
        let [a, b] = [0.25f32, -0.25].map(|y| c.intersect(1, &Ray::new(Vec3::new(1.5, y, 3.0), -Vec3::Z)).unwrap());
        assert!((a.t - (3.0 - 0.1875f32.sqrt())).abs() < 1e-4 && (b.t - a.t).abs() < 1e-5, "{a:?} {b:?}");
        assert!(((a.v - 0.5).abs() - 0.25).abs() < 1e-3 && (a.v + b.v - 1.0).abs() < 1e-3, "{a:?} {b:?}");
        // Past the first segment's round end x = 0: the end sphere, at x = -0.3, z = 0.4.
        let ray = Ray::new(Vec3::new(-0.3, 0.0, 3.0), -Vec3::Z);
        let h = c.intersect(0, &ray).unwrap();
        assert!((h.t - 2.6).abs() < 1e-4 && h.u == 0.0, "{h:?}");
        // From inside, on the axis at x = 0.9, along +x: the sphere closing segment 0 at the
        // joint (centre x = 1) is left at x = 1.5, inside segment 1's tube: interior, no
        // hit. Segment 1's round end is left at x = 2.5, t = 1.6. The same backwards.
        let ray = Ray::new(Vec3::new(0.9, 0.0, 0.0), Vec3::X);
        assert_eq!(c.intersect(0, &ray), None);
        let h = c.intersect(1, &ray).unwrap();
        assert!((h.t - 1.6).abs() < 1e-4 && (h.u - 1.0).abs() < 1e-6, "{h:?}");
        let ray = Ray::new(Vec3::new(1.1, 0.0, 0.0), -Vec3::X);
        assert_eq!(c.intersect(1, &ray), None);
        let h = c.intersect(0, &ray).unwrap();
        assert!((h.t - 1.6).abs() < 1e-4 && h.u.abs() < 1e-6, "{h:?}");
    }

    /// A bent strand, cut into leaves: the quadratic (0,0,0) (1,2,0) (2,0,0) of radius 0.05 is
    /// p(u) = (2u, 4u(1 - u), 0). Rays down z onto p(½) = (1, 1) and p(¼) = (0.5, 0.75) meet
    /// the tube's top, z = 0.05, at t = 2.95, the leaves' chords within 0.02r of the curve.
    #[test]
    fn bent_strand_hits_by_hand() {
        let c = Curve::new(vec![Bezier::new(&[Vec4::new(0.0, 0.0, 0.0, 0.05), Vec4::new(1.0, 2.0, 0.0, 0.05), Vec4::new(2.0, 0.0, 0.0, 0.05)]).unwrap()], MaterialId(0));
        assert!(c.cubics[0].1 > 0);
        for (x, y, u) in [(1.0, 1.0, 0.5), (0.5, 0.75, 0.25)] {
            let h = c.intersect(0, &Ray::new(Vec3::new(x, y, 3.0), -Vec3::Z)).unwrap();
            assert!((h.t - 2.95).abs() < 2e-3 && (h.u - u).abs() < 1e-2, "{x} {y}: {h:?}");
        }
        assert!(c.intersect(0, &Ray::new(Vec3::new(1.0, 1.1, 3.0), -Vec3::Z)).is_none());
        // Its end raised to z = 1 (z = u², so the second half is the nearer from above): over
        // p(½) = (1, 1, ¼) the axis leans along (2, 0, 1)/√5, and the vertical line meets the
        // tube r·√5/2 above the axis: t ≈ 3 - ¼ - 0.0559.
        let c = Curve::new(vec![Bezier::new(&[Vec4::new(0.0, 0.0, 0.0, 0.05), Vec4::new(1.0, 2.0, 0.0, 0.05), Vec4::new(2.0, 0.0, 1.0, 0.05)]).unwrap()], MaterialId(0));
        let h = c.intersect(0, &Ray::new(Vec3::new(1.0, 1.0, 3.0), -Vec3::Z)).unwrap();
        assert!((h.t - (2.75 - 0.05 * 5f32.sqrt() / 2.0)).abs() < 1e-2 && (h.u - 0.5).abs() < 3e-2, "{h:?}");
    }

    /// The surface at hits given by hand (the point is o + t·d): the normal is the offset from
    /// the axis at u without its part along the axis, but at the strand's two round ends the
    /// whole offset; uv.x runs over the strand, (seg + u)/2; ∂p/∂u is the segment's tangent
    /// times the 2 segments, ∂p/∂v = n × axis · 2r.
    #[test]
    fn surface_by_hand() {
        let c = strand();
        // Seg 1 at u = ½ (centre (1.5, 0, 0)), the point (1.6, 0, 0.5) from z = 3 down (a
        // direction of length 2, t = 1.25): offset (0.1, 0, 0.5), less its x part: n = ẑ.
        let ray = Ray::new(Vec3::new(1.6, 0.0, 3.0), Vec3::new(0.0, 0.0, -2.0));
        let g = c.surface(1, &ray, 1.25, 0.5, 0.25);
        assert_eq!((g.p, g.ng, g.ns, g.uv), (Vec3::new(1.6, 0.0, 0.5), Vec3::Z, Vec3::Z, Vec2::new(0.75, 0.25)));
        assert_eq!((g.dpdu, g.dpdv), (Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)));
        // γ₆₄·(|o| + |t·d| + |p|, largest coordinates 3 + 2.5 + 1.6) + 10⁻⁴·r
        let e = 64.0 * f64::from(f32::EPSILON) * 0.5 * 7.1 + 1e-4 * 0.5;
        assert!((g.p_error.as_dvec3() - glam::DVec3::splat(e)).abs().max_element() < 1e-3 * e, "{} vs {e}", g.p_error);
        // The joint x = 1 is no end: seg 0 at u = 1 and seg 1 at u = 0 drop the x part too.
        let ray = Ray::new(Vec3::new(1.3, 0.0, 3.0), -Vec3::Z);
        assert_eq!(c.surface(0, &ray, 2.6, 1.0, 0.5).ng, Vec3::Z);
        assert_eq!(c.surface(1, &ray, 2.6, 0.0, 0.5).ng, Vec3::Z);
        // The strand's ends keep the whole offset: (0.3, 0, 0.4)/0.5 past x = 2, and its mirror
        // past x = 0.
        assert!((c.surface(1, &Ray::new(Vec3::new(2.3, 0.0, 3.0), -Vec3::Z), 2.6, 1.0, 0.5).ng - Vec3::new(0.6, 0.0, 0.8)).length() < 1e-6);
        let g = c.surface(0, &Ray::new(Vec3::new(-0.3, 0.0, 3.0), -Vec3::Z), 2.6, 0.0, 0.5);
        assert!((g.ng - Vec3::new(-0.6, 0.0, 0.8)).length() < 1e-6 && g.uv.x == 0.0, "{}", g.ng);
        // A point on the axis has no offset: any unit vector across it will do.
        let g = c.surface(0, &Ray::new(Vec3::new(0.5, 0.0, 3.0), -Vec3::Z), 3.0, 0.5, 0.5);
        assert!((g.ng.length() - 1.0).abs() < 1e-6 && g.ng.x.abs() < 1e-6, "{}", g.ng);
    }

    /// A quadratic whose first two control points coincide has no tangent at u = 0: the
    /// chord's direction stands in, p(1) - p(0) = (1, 2, 0) - (1, 0, 0) along ŷ, so the y
    /// part of the offset is dropped. (The hit is a point given by hand, not on the tube.)
    #[test]
    fn surface_where_the_tangent_vanishes_uses_the_chord() {
        let cp = |y: f32| Vec4::new(1.0, y, 0.0, 0.25);
        let c = Curve::new(vec![Bezier::new(&[cp(-1.0), cp(0.0)]).unwrap(), Bezier::new(&[cp(0.0), cp(0.0), cp(2.0)]).unwrap()], MaterialId(0));
        let g = c.surface(1, &Ray::new(Vec3::new(1.0, 0.3, 3.0), -Vec3::Z), 2.6, 0.0, 0.5);
        // ∂p/∂v = ẑ × ŷ · 2r, r = ¼
        assert_eq!((g.ng, g.dpdu, g.dpdv), (Vec3::Z, Vec3::ZERO, Vec3::new(-0.5, 0.0, 0.0)));
    }
}
