//! A primitive's box and index in 32 bytes ([`PrimRef`], Embree's layout) and a box held
//! in SIMD registers ([`Box3`]): what the top-down builders (binned SAH, SBVH) stream
//! through at every level of the tree.

use glam::{Vec3A, Vec4};
use raylab_core::Aabb;

/// A primitive's box and its index in the input, in 32 bytes (Embree's layout): the index
/// rides in the fourth lane of the minimum, which the box arithmetic carries along and
/// ignores. Binning and partitioning stream these through memory at every level of the
/// tree; at 48 bytes (a separate index and padding) they moved half as much again.
///
/// The fourth lanes always hold normal floats, so that the centroid's arithmetic, which
/// runs on all four lanes, never meets a denormal (microcode assists on many CPUs): the
/// index is stored as the bits `id + 2²³` (exponent at least 1; finite below
/// [`MAX_PRIMS`]) and the maximum's fourth lane is 1.
#[derive(Clone, Copy)]
pub(super) struct PrimRef {
    min_id: Vec4,
    pub(super) max: Vec3A,
}

const _: () = assert!(std::mem::size_of::<PrimRef>() == 32);

/// Primitives a binary BVH can index ([`PrimRef`]'s encoding).
pub(super) const MAX_PRIMS: usize = 1 << 30;
const ID_BIAS: u32 = 1 << 23;

impl PrimRef {
    #[inline]
    pub(super) fn new(min: Vec3A, max: Vec3A, id: u32) -> Self {
        Self { min_id: min.extend(f32::from_bits(id + ID_BIAS)), max: Vec3A::from_vec4(max.extend(1.0)) }
    }

    #[inline]
    pub(super) fn min(&self) -> Vec3A {
        Vec3A::from_vec4(self.min_id)
    }

    #[inline]
    pub(super) fn id(&self) -> u32 {
        self.min_id.w.to_bits() - ID_BIAS
    }

    /// The box, without the index.
    #[inline]
    pub(super) fn bounds(&self) -> Box3 {
        Box3 { min: self.min(), max: self.max }
    }

    /// The same arithmetic as [`Aabb::centroid`], lane by lane.
    #[inline]
    pub(super) fn centroid(&self) -> Vec3A {
        0.5 * (self.min() + self.max)
    }
}

/// A box held in SIMD registers while building ([`Aabb`] keeps 12-byte `Vec3`s).
#[derive(Clone, Copy)]
pub(super) struct Box3 {
    pub(super) min: Vec3A,
    pub(super) max: Vec3A,
}

impl Box3 {
    pub(super) const EMPTY: Box3 = Box3 { min: Vec3A::splat(f32::INFINITY), max: Vec3A::splat(f32::NEG_INFINITY) };

    #[inline]
    pub(super) fn grow(&mut self, min: Vec3A, max: Vec3A) {
        self.min = self.min.min(min);
        self.max = self.max.max(max);
    }

    #[inline]
    pub(super) fn union(self, o: Box3) -> Box3 {
        Box3 { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// [`Aabb::half_area`]'s formula, in the same order.
    #[inline]
    pub(super) fn half_area(&self) -> f32 {
        let d = (self.max - self.min).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    #[inline]
    pub(super) fn intersection(self, o: Box3) -> Box3 {
        Box3 { min: self.min.max(o.min), max: self.max.min(o.max) }
    }

    #[inline]
    pub(super) fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    pub(super) fn from_aabb(b: &Aabb) -> Box3 {
        Box3 { min: b.min.into(), max: b.max.into() }
    }

    pub(super) fn aabb(&self) -> Aabb {
        Aabb { min: self.min.into(), max: self.max.into() }
    }
}

/// The whole parts of `t`'s lanes, each in `[0, 2³¹)`: one conversion for the three axes.
#[inline(always)]
pub(super) fn truncate(t: Vec3A) -> [u32; 3] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128, _mm_cvttps_epi32};
        // SAFETY: SSE2 is in the x86-64 baseline; the result holds four i32.
        let [x, y, z, _]: [i32; 4] = unsafe { std::mem::transmute(_mm_cvttps_epi32(__m128::from(t))) };
        [x as u32, y as u32, z as u32]
    }
    #[cfg(not(target_arch = "x86_64"))]
    // SAFETY: each lane is in [0, 2³¹), so it converts.
    t.to_array().map(|v| unsafe { v.to_int_unchecked::<u32>() })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An index survives the trip through the fourth lane, whose float stays normal (no
    /// denormal in the centroid's arithmetic), and the box lanes are untouched.
    #[test]
    fn prim_refs_carry_their_index_in_a_normal_float() {
        let (min, max) = (Vec3A::new(-1.0, 2.0, -3.5), Vec3A::new(4.0, 5.0, 6.0));
        for id in [0, 1, 7, (1 << 23) - 1, 1 << 23, 123_456_789, MAX_PRIMS as u32 - 1] {
            let r = PrimRef::new(min, max, id);
            assert_eq!(r.id(), id);
            assert!(r.min_id.w.is_normal() && r.min_id.w.is_finite(), "id {id}: {}", r.min_id.w);
            assert_eq!((r.min(), r.max), (min, max));
            assert_eq!(r.centroid(), Vec3A::new(1.5, 3.5, 1.25));
        }
    }
}
