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
