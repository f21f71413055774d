//! Sixteen rays per 512-bit register (AVX-512F and VL), as Embree's `rtcIntersect16`: the
//! default packet path of 8-wide nodes on CPUs that run it.

use std::arch::x86_64::*;

use raylab_core::Ray;

use super::{Extremes, Vector, RAY_F32};
use crate::wide::node::Layout;
use crate::wide::packet::PACKET;
use crate::wide::WideBvh;
use crate::{Counters, Hit, Primitives};

/// The AVX-512 token: made only where the CPU has AVX-512F and VL, AVX2, BMI1 and BMI2.
#[derive(Clone, Copy)]
pub(in crate::wide) struct X16(());

impl X16 {
    /// The token, where the CPU runs this width.
    #[cfg(test)]
    pub(super) fn detect() -> Option<X16> {
        use std::is_x86_feature_detected as has;
        (has!("avx512f") && has!("avx512vl") && has!("avx2") && has!("bmi1") && has!("bmi2")).then_some(X16(()))
    }
}

/// Sixteen lanes, aligned for 512-bit loads and stores.
type Lanes = super::Lanes<__m512, PACKET>;
const _: () = assert!(std::mem::align_of::<Lanes>() == 64 && std::mem::size_of::<Lanes>() == 64);

/// Closest hits of `rays` (1 to [`PACKET`]) into `out`: [`super::closest`] with AVX-512.
///
/// # Safety
/// The CPU must support AVX-512F and VL, AVX2, BMI1 and BMI2.
#[target_feature(enable = "avx2,avx512f,avx512vl,bmi1,bmi2")]
pub(in crate::wide) unsafe fn closest<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool>(bvh: &WideBvh<W, N>, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) -> bool {
    super::closest::<X16, P, W, N, COUNT>(X16(()), bvh, prims, rays, out, c)
}

// SAFETY: `X16` is made only by `closest`, whose callers checked the features, and by
// `detect`, which checks them.
unsafe impl Vector for X16 {
    const RAYS: usize = PACKET;
    const ALL: u32 = 0xFFFF;
    type F = __m512;
    type Lanes = Lanes;

    one_intrinsic_each!(__m512, _mm512_set1_ps, add = _mm512_add_ps, sub = _mm512_sub_ps, mul = _mm512_mul_ps, div = _mm512_div_ps, min = _mm512_min_ps, max = _mm512_max_ps);

    // SAFETY (every method below): the token proves the CPU runs its instructions.
    #[inline(always)]
    fn abs(self, a: __m512) -> __m512 {
        unsafe { _mm512_abs_ps(a) }
    }
    #[inline(always)]
    fn cmp<const P: i32>(self, a: __m512, b: __m512) -> u32 {
        unsafe { u32::from(_mm512_cmp_ps_mask::<P>(a, b)) }
    }
    #[inline(always)]
    fn blend(self, m: u32, a: __m512, b: __m512) -> __m512 {
        unsafe { _mm512_mask_blend_ps(m as __mmask16, a, b) }
    }
    #[inline(always)]
    fn signs_differ(self, a: __m512, b: __m512, c: __m512) -> u32 {
        let bits = _mm512_castps_si512;
        // The sign bits differ: read as integers, below zero.
        unsafe { u32::from(_mm512_cmplt_epi32_mask(_mm512_or_si512(_mm512_xor_si512(bits(a), bits(b)), _mm512_xor_si512(bits(a), bits(c))), _mm512_setzero_si512())) }
    }
    #[inline(always)]
    fn below_u32(self, a: __m512, b: __m512) -> u32 {
        unsafe { u32::from(_mm512_cmplt_epu32_mask(_mm512_castps_si512(a), _mm512_castps_si512(b))) }
    }
    #[inline(always)]
    fn least_of(self, v: __m512) -> f32 {
        unsafe { _mm512_reduce_min_ps(v) }
    }
    #[inline(always)]
    fn most_of(self, v: __m512) -> f32 {
        unsafe { _mm512_reduce_max_ps(v) }
    }
    #[inline(always)]
    fn store(self, v: __m512) -> Lanes {
        let mut l = Lanes::new([0.0; PACKET]);
        // `Lanes` is 64-byte aligned.
        unsafe { _mm512_store_ps(l.as_mut_ptr(), v) };
        l
    }
    #[inline(always)]
    fn load(self, l: &Lanes) -> __m512 {
        // `Lanes` is 64-byte aligned.
        unsafe { _mm512_load_ps(l.as_ptr()) }
    }

    // The two below keep their closures in functions with the features enabled (closures
    // inherit them), so nothing is left out of line.
    #[inline(always)]
    fn load_rays(self, rays: &[Ray]) -> [__m512; RAY_F32] {
        unsafe { load_rays(rays) }
    }
    #[inline(always)]
    fn extremes(self, origin: [__m512; 3], inv: [__m512; 3], t_min: __m512) -> Extremes {
        unsafe { extremes(origin, inv, t_min) }
    }
}

/// [`Vector::load_rays`]: eight loads of two rays each, transposed (eight 16-lane gathers
/// cost more).
#[inline]
#[target_feature(enable = "avx512f")]
fn load_rays(rays: &[Ray]) -> [__m512; RAY_F32] {
    let n = rays.len();
    let padded: [Ray; PACKET];
    let src = if n == PACKET {
        rays.as_ptr()
    } else {
        padded = std::array::from_fn(|r| rays[r.min(n - 1)]);
        padded.as_ptr()
    };
    // SAFETY: `src` points to 16 rays of 8 f32 each, two per 64-byte load.
    transpose(std::array::from_fn(|k| unsafe { _mm512_loadu_ps(src.cast::<f32>().add(16 * k)) }))
}

/// [`Vector::extremes`]: thirteen reductions at once ([`least_of_each`]), maxima as negated
/// minima of the negated lanes (exact for finite values).
#[inline]
#[target_feature(enable = "avx512f")]
fn extremes(origin: [__m512; 3], inv: [__m512; 3], t_min: __m512) -> Extremes {
    let neg = |x: __m512| _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(x), _mm512_set1_epi32(i32::MIN)));
    let [o0, o1, o2] = origin;
    let [i0, i1, i2] = inv;
    let least = least_of_each([o0, o1, o2, neg(o0), neg(o1), neg(o2), i0, i1, i2, neg(i0), neg(i1), neg(i2), t_min, t_min, t_min, t_min]);
    Extremes { origin: [0, 1, 2].map(|a| [least[a], -least[3 + a]]), inv: [0, 1, 2].map(|a| [least[6 + a], -least[9 + a]]), t_min: least[12] }
}

/// Lane `i` of `[a | b]`'s even lanes (`EVEN[i] = 2i`) and odd lanes, as indices of
/// `_mm512_permutex2var_ps`.
const EVEN: [i32; 16] = [0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30];
const ODD: [i32; 16] = [1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31];

/// Sixteen rays of eight f32, two per register (rays `2k` and `2k + 1` in `v[k]`), as
/// eight registers of one field each (field `f` of ray `r` in lane `r` of the result's
/// `f`-th): three stages that each split register pairs into even and odd lanes.
#[inline]
#[target_feature(enable = "avx512f")]
fn transpose(v: [__m512; RAY_F32]) -> [__m512; RAY_F32] {
    // SAFETY: the index arrays hold 16 i32.
    let (even, odd) = unsafe { (_mm512_loadu_si512(EVEN.as_ptr().cast()), _mm512_loadu_si512(ODD.as_ptr().cast())) };
    let split = |a: __m512, b: __m512| (_mm512_permutex2var_ps(a, even, b), _mm512_permutex2var_ps(a, odd, b));
    // Stage `s` splits registers `r` and `r | 1 << s`.
    let [a0, a1, a2, a3, a4, a5, a6, a7] = v;
    let ((a0, a1), (a2, a3), (a4, a5), (a6, a7)) = (split(a0, a1), split(a2, a3), split(a4, a5), split(a6, a7));
    let ((a0, a2), (a1, a3), (a4, a6), (a5, a7)) = (split(a0, a2), split(a1, a3), split(a4, a6), split(a5, a7));
    let ((a0, a4), (a1, a5), (a2, a6), (a3, a7)) = (split(a0, a4), split(a1, a5), split(a2, a6), split(a3, a7));
    [a0, a1, a2, a3, a4, a5, a6, a7]
}

/// The least lane of each of sixteen registers: four stages that each pair registers and
/// take the lesser of each pair of neighbouring lanes (the even and odd lanes of `[a | b]`):
/// 30 shuffles for sixteen minima, where each reduction alone takes four.
#[inline]
#[target_feature(enable = "avx512f")]
fn least_of_each(v: [__m512; 16]) -> [f32; 16] {
    // SAFETY: the index arrays hold 16 i32.
    let (even, odd) = unsafe { (_mm512_loadu_si512(EVEN.as_ptr().cast()), _mm512_loadu_si512(ODD.as_ptr().cast())) };
    let least = |a: __m512, b: __m512| _mm512_min_ps(_mm512_permutex2var_ps(a, even, b), _mm512_permutex2var_ps(a, odd, b));
    let v: [__m512; 8] = std::array::from_fn(|k| least(v[2 * k], v[2 * k + 1]));
    let v: [__m512; 4] = std::array::from_fn(|k| least(v[2 * k], v[2 * k + 1]));
    let v: [__m512; 2] = std::array::from_fn(|k| least(v[2 * k], v[2 * k + 1]));
    let mut out = Lanes::new([0.0; PACKET]);
    // SAFETY: `Lanes` is 64-byte aligned.
    unsafe { _mm512_store_ps(out.as_mut_ptr(), least(v[0], v[1])) };
    out.lanes
}
