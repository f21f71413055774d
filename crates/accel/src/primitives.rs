use std::ops::Range;

use raylab_core::{Aabb, Ray, Vec3};

/// A hit on one primitive: distance and the primitive's own surface parameters
/// (barycentrics for triangles, angles for spheres, ...).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

/// A hit found by a structure: which primitive, and where on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub prim: u32,
    pub u: f32,
    pub v: f32,
}

impl Hit {
    pub fn new(prim: u32, h: PrimHit) -> Self {
        Self { t: h.t, prim, u: h.u, v: h.v }
    }
}

/// What a structure indexes into. Builders read only bounds and centroids; leaves call
/// `intersect`, which generics inline into the traversal loop.
pub trait Primitives: Sync {
    fn len(&self) -> usize;

    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Bounds of primitive `i`; finite for every `i < len()`.
    fn bounds(&self, i: u32) -> Aabb;

    fn centroid(&self, i: u32) -> Vec3 {
        self.bounds(i).centroid()
    }

    /// Hit with `t` in `(ray.t_min, ray.t_max]`, or `None`.
    fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit>;

    /// The vertices of primitive `i` when it is a triangle whose [`Primitives::intersect`]
    /// is exactly `raylab_core::intersect::triangle(ray, p0, p1, p2)` (same `t`, same
    /// barycentrics as `u`, `v`); `None` otherwise (the default). Wide BVHs copy such
    /// triangles into their leaves and test them without calling `intersect`; every other
    /// primitive still goes through `intersect`.
    fn triangle(&self, _i: u32) -> Option<[Vec3; 3]> {
        None
    }

    /// Whether [`Primitives::triangle`] is `Some` for primitive `i`, without loading the
    /// vertices where the implementation can tell.
    fn is_triangle(&self, i: u32) -> bool {
        self.triangle(i).is_some()
    }

    /// Bounds of the part of primitive `i` that lies inside `clip`, for spatial splits
    /// (kd-tree "perfect splits", SBVH, grid cells). The default, `bounds ∩ clip`, is
    /// conservative; triangles should clip exactly (`raylab_core::clip::triangle_bounds`, as
    /// the renderer's `Geometry` and the testkit's `Soup` do), which keeps a triangle out of
    /// the cells and children that its box overlaps but it does not.
    fn clipped_bounds(&self, i: u32, clip: &Aabb) -> Aabb {
        self.bounds(i).intersection(*clip)
    }

    /// The scene's objects as consecutive ranges of primitive indices (one mesh, one
    /// sphere, ...), for per-object bounding boxes. Default: one object per primitive.
    fn objects(&self) -> Vec<Range<u32>> {
        (0..self.len() as u32).map(|i| i..i + 1).collect()
    }
}

/// Bounds of all primitives.
pub fn total_bounds<P: Primitives + ?Sized>(prims: &P) -> Aabb {
    (0..prims.len() as u32).fold(Aabb::EMPTY, |b, i| b.union(prims.bounds(i)))
}

/// Boxes as primitives for this crate's unit tests (the testkit's `Boxes` implements the
/// trait of another build of this crate): a ray hits where it enters a box; clipping is the
/// default `bounds ∩ clip`.
#[cfg(test)]
pub(crate) struct TestBoxes(pub Vec<Aabb>);

#[cfg(test)]
impl Primitives for TestBoxes {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn bounds(&self, i: u32) -> Aabb {
        self.0[i as usize]
    }
    fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
        let (t0, _) = self.0[i as usize].intersect_ray(ray)?;
        (t0 > ray.t_min && t0 <= ray.t_max).then_some(PrimHit { t: t0, u: 0.0, v: 0.0 })
    }
}
