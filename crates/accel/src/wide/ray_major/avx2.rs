//! Eight rays per 256-bit register (AVX2), as Embree's `rtcIntersect8`: CPUs without
//! AVX-512 trace a 16-ray camera tile as two such packets of 4×2 rays. Masks come from
//! `movemask` and are turned back into lane masks where a blend needs one.

use std::arch::x86_64::*;

use raylab_core::Ray;

use super::{Extremes, Vector, RAY_F32};
use crate::wide::node::Layout;
use crate::wide::WideBvh;
use crate::{Counters, Hit, Primitives};

/// Rays per packet.
pub(in crate::wide) const RAYS: usize = 8;

/// The AVX2 token: made only where the CPU has AVX2.
#[derive(Clone, Copy)]
pub(in crate::wide) struct X8(());

impl X8 {
    /// The token, where the CPU runs this width.
    #[cfg(test)]
    pub(super) fn detect() -> Option<X8> {
        std::is_x86_feature_detected!("avx2").then_some(X8(()))
    }
}

/// Eight lanes, aligned for 256-bit loads and stores.
type Lanes = super::Lanes<__m256, RAYS>;
const _: () = assert!(std::mem::align_of::<Lanes>() == 32 && std::mem::size_of::<Lanes>() == 32);

/// Closest hits of `rays` (1 to [`RAYS`]) into `out`: [`super::closest`] with AVX2.
///
/// # Safety
/// The CPU must support AVX2.
#[target_feature(enable = "avx2")]
pub(in crate::wide) unsafe fn closest<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool>(bvh: &WideBvh<W, N>, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) -> bool {
    super::closest::<X8, P, W, N, COUNT>(X8(()), bvh, prims, rays, out, c)
}

/// The lanes of `m`'s bits as a lane mask (all bits set).
#[inline]
#[target_feature(enable = "avx2")]
fn lane_mask(m: u32) -> __m256 {
    let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(m as i32), lane_bits), lane_bits))
}

// SAFETY: `X8` is made only by `closest`, whose callers checked AVX2, and by `detect`,
// which checks it.
unsafe impl Vector for X8 {
    const RAYS: usize = RAYS;
    const ALL: u32 = 0xFF;
    type F = __m256;
    type Lanes = Lanes;

    one_intrinsic_each!(__m256, _mm256_set1_ps, add = _mm256_add_ps, sub = _mm256_sub_ps, mul = _mm256_mul_ps, div = _mm256_div_ps, min = _mm256_min_ps, max = _mm256_max_ps);

    // SAFETY (every method below): the token proves the CPU runs its instructions.
    #[inline(always)]
    fn abs(self, a: __m256) -> __m256 {
        unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), a) }
    }
    #[inline(always)]
    fn cmp<const P: i32>(self, a: __m256, b: __m256) -> u32 {
        unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<P>(a, b)) as u32 }
    }
    #[inline(always)]
    fn blend(self, m: u32, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_blendv_ps(a, b, lane_mask(m)) }
    }
    #[inline(always)]
    fn signs_differ(self, a: __m256, b: __m256, c: __m256) -> u32 {
        // `movemask` reads the sign bits.
        unsafe { _mm256_movemask_ps(_mm256_or_ps(_mm256_xor_ps(a, b), _mm256_xor_ps(a, c))) as u32 }
    }
    #[inline(always)]
    fn below_u32(self, a: __m256, b: __m256) -> u32 {
        // Unsigned order: both with the top bit flipped, compared as signed.
        unsafe {
            let top = _mm256_set1_epi32(i32::MIN);
            let flip = |x: __m256| _mm256_xor_si256(_mm256_castps_si256(x), top);
            _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(flip(b), flip(a)))) as u32
        }
    }
    #[inline(always)]
    fn least_of(self, v: __m256) -> f32 {
        unsafe {
            let m = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
            let m = _mm_min_ps(m, _mm_movehl_ps(m, m));
            _mm_cvtss_f32(_mm_min_ss(m, _mm_movehdup_ps(m)))
        }
    }
    #[inline(always)]
    fn most_of(self, v: __m256) -> f32 {
        unsafe {
            let m = _mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
            let m = _mm_max_ps(m, _mm_movehl_ps(m, m));
            _mm_cvtss_f32(_mm_max_ss(m, _mm_movehdup_ps(m)))
        }
    }
    #[inline(always)]
    fn store(self, v: __m256) -> Lanes {
        let mut l = Lanes::new([0.0; RAYS]);
        // `Lanes` is 32-byte aligned.
        unsafe { _mm256_store_ps(l.as_mut_ptr(), v) };
        l
    }
    #[inline(always)]
    fn load(self, l: &Lanes) -> __m256 {
        // `Lanes` is 32-byte aligned.
        unsafe { _mm256_load_ps(l.as_ptr()) }
    }

    // The two below keep their closures in functions with AVX2 enabled (closures inherit
    // it), so nothing is left out of line.
    #[inline(always)]
    fn load_rays(self, rays: &[Ray]) -> [__m256; RAY_F32] {
        unsafe { load_rays(rays) }
    }
    #[inline(always)]
    fn extremes(self, origin: [__m256; 3], inv: [__m256; 3], t_min: __m256) -> Extremes {
        unsafe { extremes(self, origin, inv, t_min) }
    }
}

/// [`Vector::load_rays`]: one 32-byte load per ray, transposed.
#[inline]
#[target_feature(enable = "avx2")]
fn load_rays(rays: &[Ray]) -> [__m256; RAY_F32] {
    let n = rays.len();
    let padded: [Ray; RAYS];
    let src = if n == RAYS {
        rays.as_ptr()
    } else {
        padded = std::array::from_fn(|r| rays[r.min(n - 1)]);
        padded.as_ptr()
    };
    // SAFETY: `src` points to 8 rays of 8 f32 each, one per 32-byte load.
    transpose(std::array::from_fn(|r| unsafe { _mm256_loadu_ps(src.cast::<f32>().add(RAY_F32 * r)) }))
}

/// [`Vector::extremes`], reduction by reduction.
#[inline]
#[target_feature(enable = "avx2")]
fn extremes(v: X8, origin: [__m256; 3], inv: [__m256; 3], t_min: __m256) -> Extremes {
    Extremes { origin: origin.map(|o| [v.least_of(o), v.most_of(o)]), inv: inv.map(|i| [v.least_of(i), v.most_of(i)]), t_min: v.least_of(t_min) }
}

/// Eight rays of eight f32, one per register, as eight registers of one field each
/// (field `f` of ray `r` in lane `r` of the result's `f`-th): the usual 8×8 transpose in
/// three stages (interleave pairs, then quads, then 128-bit halves).
#[inline]
#[target_feature(enable = "avx2")]
fn transpose(v: [__m256; RAY_F32]) -> [__m256; RAY_F32] {
    let [r0, r1, r2, r3, r4, r5, r6, r7] = v;
    let (t0, t1, t2, t3) = (_mm256_unpacklo_ps(r0, r1), _mm256_unpackhi_ps(r0, r1), _mm256_unpacklo_ps(r2, r3), _mm256_unpackhi_ps(r2, r3));
    let (t4, t5, t6, t7) = (_mm256_unpacklo_ps(r4, r5), _mm256_unpackhi_ps(r4, r5), _mm256_unpacklo_ps(r6, r7), _mm256_unpackhi_ps(r6, r7));
    let (q0, q1, q2, q3) = (_mm256_shuffle_ps::<0x44>(t0, t2), _mm256_shuffle_ps::<0xEE>(t0, t2), _mm256_shuffle_ps::<0x44>(t1, t3), _mm256_shuffle_ps::<0xEE>(t1, t3));
    let (q4, q5, q6, q7) = (_mm256_shuffle_ps::<0x44>(t4, t6), _mm256_shuffle_ps::<0xEE>(t4, t6), _mm256_shuffle_ps::<0x44>(t5, t7), _mm256_shuffle_ps::<0xEE>(t5, t7));
    let lo = |a: __m256, b: __m256| _mm256_permute2f128_ps::<0x20>(a, b);
    let hi = |a: __m256, b: __m256| _mm256_permute2f128_ps::<0x31>(a, b);
    [lo(q0, q4), lo(q1, q5), lo(q2, q6), lo(q3, q7), hi(q0, q4), hi(q1, q5), hi(q2, q6), hi(q3, q7)]
}
