//! The per-node and per-leaf kernels: a slab test of all `W` child boxes at once, and a
//! watertight test of a block of four triangles with the ray's shear computed once.
//!
//! Each kernel has a portable form and a SIMD form (`std::arch`: AVX2 for 8 lanes, SSE2
//! for 4) doing the same IEEE operations in the same order — no FMA, whose single rounding
//! would change results — so both give bit-identical answers; the tests compare them.

use raylab_core::intersect::ShearedRay;

use super::node::{ChildRef, Layout, TriBlock, WideNode, EMPTY};
use super::ray::{BlockRay, RayBoxes};

/// The f32 node's boxes are tested by the kernels below, chosen by width: AVX2 for eight
/// lanes, SSE2 for four, else the portable kernel.
// SAFETY: f32 and u32 fields only, 224 or 128 bytes, `align(32)`.
unsafe impl<const W: usize> Layout<W> for WideNode<W> {
    const NAME: &'static str = "f32";
    const EXACT: bool = true;

    fn encode(node: &WideNode<W>) -> Self {
        *node
    }

    #[inline(always)]
    fn with_decoded<R>(&self, f: impl FnOnce(&WideNode<W>) -> R) -> R {
        f(self)
    }

    #[inline(always)]
    fn decoded<'a>(&'a self, _: &'a mut std::mem::MaybeUninit<WideNode<W>>) -> &'a WideNode<W> {
        self
    }

    #[inline(always)]
    fn child(&self, lane: usize) -> ChildRef {
        self.child[lane]
    }

    #[inline(always)]
    fn boxes<const SIMD: bool>(&self, r: &RayBoxes, t_max: f32, tnear: &mut [f32; W]) -> u32 {
        child_boxes::<W, SIMD>(self, r, t_max, tnear)
    }
}

/// [`Layout::boxes`] of an f32 node: the SIMD kernel of its width, or the portable one.
#[inline(always)]
pub(super) fn child_boxes<const W: usize, const SIMD: bool>(node: &WideNode<W>, r: &RayBoxes, t_max: f32, tnear: &mut [f32; W]) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if SIMD {
        if W == 8 {
            // SAFETY: `W == 8`, so these are the same types; SIMD = true with W = 8 is only
            // instantiated inside functions with AVX2 enabled (`closest_avx2`, `closest_avx512`,
            // ...) that `Kernel::available` selects after detecting their features.
            return unsafe { boxes_avx2(&*(node as *const WideNode<W>).cast::<WideNode<8>>(), r, t_max, &mut *(tnear as *mut [f32; W]).cast::<[f32; 8]>()) };
        }
        if W == 4 {
            // SAFETY: `W == 4`: the same types.
            return unsafe { boxes_sse(&*(node as *const WideNode<W>).cast::<WideNode<4>>(), r, t_max, &mut *(tnear as *mut [f32; W]).cast::<[f32; 4]>()) };
        }
    }
    boxes_portable(node, r, t_max, tnear)
}

/// Which children of `node` the ray enters within `[t_min, t_max]` (bit `l` for lane `l`)
/// and their entry distances. Callers pass `t_max` already widened by [`ROBUST_FAR`](super::ray::ROBUST_FAR):
/// the entry distance of a flat box (coplanar triangles) may round a few ulps above the
/// distance the triangle kernel computes for a hit inside it, and such a box must not be
/// culled by that hit. A NaN slab distance (a ray lying in a slab's plane, `0 · ∞`)
/// constrains nothing, as in `Aabb::intersect`.
///
/// Rays whose distances cannot be NaN and start at `t_min >= 0` ([`RayBoxes::by_bits`],
/// nearly all) reduce them in integer order: the entry distance is the greatest of `t_min`
/// and the axes' near distances by their bits read as `i32`, the exit distance the least
/// of `t_max` and the far distances, and a box is entered when entry `<=` exit as floats.
/// Bits order non-negative floats as floats and put every negative one below them, so the
/// entry distance is exactly the float maximum (a negative near distance never exceeds
/// `t_min`), and the exit distance is the float minimum when no far distance is negative,
/// and negative (the box missed) when one is. One corner differs from float order, on the
/// safe side: a far distance of `-0` (an origin on the box's exit plane) makes the exit
/// `-0` even when another axis's is negative, so the box is entered at `t = 0`.
#[inline(always)]
#[allow(clippy::needless_range_loop)] // lanes index the bound rows and `tnear` alike
pub fn boxes_portable<const W: usize>(node: &WideNode<W>, r: &RayBoxes, t_max: f32, tnear: &mut [f32; W]) -> u32 {
    let mut mask = 0;
    for lane in 0..W {
        let (t0, t1) = if !r.by_bits {
            let (mut t0, mut t1) = (r.t_min, t_max);
            for a in 0..3 {
                let near = (node.bounds[r.near[a]][lane] - r.origin[a]) * r.inv[a];
                let far = (node.bounds[r.far[a]][lane] - r.origin[a]) * r.inv_far[a];
                // Written as the SIMD max/min instructions behave: `max(a, b) = a > b ? a : b`.
                t0 = if near > t0 { near } else { t0 };
                t1 = if far < t1 { far } else { t1 };
            }
            (t0, t1)
        } else {
            let key = |x: f32| x.to_bits() as i32;
            let (mut t0, mut t1) = (key(r.t_min), key(t_max));
            for a in 0..3 {
                let near = (node.bounds[r.near[a]][lane] - r.origin[a]) * r.inv[a];
                let far = (node.bounds[r.far[a]][lane] - r.origin[a]) * r.inv_far[a];
                t0 = t0.max(key(near));
                t1 = t1.min(key(far));
            }
            (f32::from_bits(t0 as u32), f32::from_bits(t1 as u32))
        };
        tnear[lane] = t0;
        mask |= u32::from(t0 <= t1) << lane;
    }
    mask
}

/// [`boxes_portable`] for eight lanes with AVX.
///
/// # Safety
/// The CPU must support AVX2 (checked by `is_x86_feature_detected!` at build).
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn boxes_avx2(node: &WideNode<8>, r: &RayBoxes, t_max: f32, tnear: &mut [f32; 8]) -> u32 {
    use std::arch::x86_64::*;
    // SAFETY: AVX2 is enabled in this function.
    let (t0, t1) = unsafe { slabs_avx2(node, r, t_max) };
    // SAFETY: `tnear` holds 8 f32.
    unsafe { _mm256_storeu_ps(tnear.as_mut_ptr(), t0) };
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32
}

/// The entry and exit distances of [`boxes_avx2`] (lane `l` hit when `t0 <= t1`).
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn slabs_avx2(node: &WideNode<8>, r: &RayBoxes, t_max: f32) -> (std::arch::x86_64::__m256, std::arch::x86_64::__m256) {
    use std::arch::x86_64::*;
    // SAFETY: each row holds 8 f32.
    let load = |row: usize| unsafe { _mm256_loadu_ps(node.bounds[row].as_ptr()) };
    // SAFETY: AVX2 is enabled in this function.
    unsafe { slabs_of_rows_avx2(&r.near.map(load), &r.far.map(load), r, t_max) }
}

/// [`slabs_avx2`] with the node's near and far planes loaded (packets load them once for
/// all their rays).
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn slabs_of_rows_avx2(lo: &[std::arch::x86_64::__m256; 3], hi: &[std::arch::x86_64::__m256; 3], r: &RayBoxes, t_max: f32) -> (std::arch::x86_64::__m256, std::arch::x86_64::__m256) {
    use std::arch::x86_64::*;
    let o = r.origin.map(|x| _mm256_set1_ps(x));
    if !r.by_bits {
        let (mut t0, mut t1) = (_mm256_set1_ps(r.t_min), _mm256_set1_ps(t_max));
        for a in 0..3 {
            let near = _mm256_mul_ps(_mm256_sub_ps(lo[a], o[a]), _mm256_set1_ps(r.inv[a]));
            let far = _mm256_mul_ps(_mm256_sub_ps(hi[a], o[a]), _mm256_set1_ps(r.inv_far[a]));
            // `max_ps(a, b)` returns `b` when either is NaN: a NaN slab is ignored.
            t0 = _mm256_max_ps(near, t0);
            t1 = _mm256_min_ps(far, t1);
        }
        return (t0, t1);
    }
    // Integer order (see `boxes_portable`).
    let near = |a: usize| _mm256_castps_si256(_mm256_mul_ps(_mm256_sub_ps(lo[a], o[a]), _mm256_set1_ps(r.inv[a])));
    let far = |a: usize| _mm256_castps_si256(_mm256_mul_ps(_mm256_sub_ps(hi[a], o[a]), _mm256_set1_ps(r.inv_far[a])));
    let key = |x: f32| _mm256_set1_epi32(x.to_bits() as i32);
    let t0 = _mm256_max_epi32(_mm256_max_epi32(near(0), near(1)), _mm256_max_epi32(near(2), key(r.t_min)));
    let t1 = _mm256_min_epi32(_mm256_min_epi32(far(0), far(1)), _mm256_min_epi32(far(2), key(t_max)));
    (_mm256_castsi256_ps(t0), _mm256_castsi256_ps(t1))
}

/// [`boxes_portable`] for four lanes with SSE2 (part of every x86-64 CPU), whose
/// integer `max` and `min` of 32-bit lanes are a compare and a select.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn boxes_sse(node: &WideNode<4>, r: &RayBoxes, t_max: f32, tnear: &mut [f32; 4]) -> u32 {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 is in the x86-64 baseline; the loads read 4 f32 of each row.
    unsafe {
        let load = |row: usize| _mm_loadu_ps(node.bounds[row].as_ptr());
        let o = r.origin.map(|x| _mm_set1_ps(x));
        let (t0, t1) = if !r.by_bits {
            let (mut t0, mut t1) = (_mm_set1_ps(r.t_min), _mm_set1_ps(t_max));
            for (a, &o) in o.iter().enumerate() {
                let near = _mm_mul_ps(_mm_sub_ps(load(r.near[a]), o), _mm_set1_ps(r.inv[a]));
                let far = _mm_mul_ps(_mm_sub_ps(load(r.far[a]), o), _mm_set1_ps(r.inv_far[a]));
                t0 = _mm_max_ps(near, t0);
                t1 = _mm_min_ps(far, t1);
            }
            (t0, t1)
        } else {
            let select = |m: __m128i, a: __m128i, b: __m128i| _mm_or_si128(_mm_and_si128(m, a), _mm_andnot_si128(m, b));
            let max = |a: __m128i, b: __m128i| select(_mm_cmpgt_epi32(a, b), a, b);
            let min = |a: __m128i, b: __m128i| select(_mm_cmpgt_epi32(a, b), b, a);
            let near = |a: usize| _mm_castps_si128(_mm_mul_ps(_mm_sub_ps(load(r.near[a]), o[a]), _mm_set1_ps(r.inv[a])));
            let far = |a: usize| _mm_castps_si128(_mm_mul_ps(_mm_sub_ps(load(r.far[a]), o[a]), _mm_set1_ps(r.inv_far[a])));
            let key = |x: f32| _mm_set1_epi32(x.to_bits() as i32);
            let t0 = max(max(near(0), near(1)), max(near(2), key(r.t_min)));
            let t1 = min(min(far(0), far(1)), min(far(2), key(t_max)));
            (_mm_castsi128_ps(t0), _mm_castsi128_ps(t1))
        };
        _mm_storeu_ps(tnear.as_mut_ptr(), t0);
        _mm_movemask_ps(_mm_cmple_ps(t0, t1)) as u32
    }
}

/// Lanes of `b` that may be hit (the portable kernel's filter): every lane except those whose three single-precision
/// edge functions are all non-zero with mixed signs, which [`ShearedRay::triangle`] rejects
/// too (it recomputes in double precision only when one of them is exactly zero). Lanes
/// that are not triangles ([`TriBlock::OTHER`]) are always candidates; empty lanes never.
/// The candidates then go through the exact scalar kernel, so the filter cannot change an
/// answer, only skip work.
#[inline(always)]
pub fn triangle_candidates(b: &TriBlock, s: &ShearedRay) -> u32 {
    let (kx, ky, kz) = (s.kx, s.ky, s.kz);
    let o = s.origin.to_array();
    let mut xs = [[0.0f32; 4]; 3];
    let mut ys = [[0.0f32; 4]; 3];
    for v in 0..3 {
        for l in 0..4 {
            let az = b.p[v][kz][l] - o[kz];
            xs[v][l] = (b.p[v][kx][l] - o[kx]) - s.sx * az;
            ys[v][l] = (b.p[v][ky][l] - o[ky]) - s.sy * az;
        }
    }
    let mut mask = 0u32;
    for l in 0..4 {
        let (ax, ay, bx, by, cx, cy) = (xs[0][l], ys[0][l], xs[1][l], ys[1][l], xs[2][l], ys[2][l]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let rejected = (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) && u != 0.0 && v != 0.0 && w != 0.0;
        let prim = b.prim[l];
        let keep = prim != EMPTY && (prim & TriBlock::OTHER != 0 || !rejected);
        mask |= u32::from(keep) << l;
    }
    mask
}

/// The watertight kernel's answers for the four lanes of a block ([`triangles_sse`]).
#[derive(Clone, Copy, Debug)]
pub struct BlockHits {
    /// Lanes hit within `(t_min, t_max]`, with their distance and barycentrics below.
    pub hit: u32,
    /// Lanes the four-wide arithmetic leaves to the scalar kernel: an edge function exactly
    /// zero or not a number (the scalar kernel recomputes them in double precision), a
    /// distance within its error bound of zero or not finite (its double-precision
    /// fallback), and primitives that are not triangles ([`TriBlock::OTHER`]).
    pub exact: u32,
    pub t: [f32; 4],
    pub u: [f32; 4],
    pub v: [f32; 4],
}

/// [`ShearedRay::triangle`] on the four lanes of a block at once (SSE2): the same IEEE
/// operations in the same order (no FMA), so a lane it decides gets exactly the scalar
/// kernel's `t` and barycentrics; the rare lanes it cannot decide are flagged
/// [`BlockHits::exact`]. The traversal then makes no call for most blocks, and a call is
/// what forces the compiler to spill the ray's constants from the vector registers.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn triangles_sse(b: &TriBlock, s: &ShearedRay, t_min: f32, t_max: f32) -> BlockHits {
    triangles_sse_for(b, &BlockRay::new(s), t_min, t_max)
}

/// [`triangles_sse`] with the ray's constants picked already ([`BlockRay`]).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn triangles_sse_for(b: &TriBlock, s: &BlockRay, t_min: f32, t_max: f32) -> BlockHits {
    block_hits_sse(b, s, t_min, t_max).unwrap_or(BlockHits { hit: 0, exact: 0, t: [0.0; 4], u: [0.0; 4], v: [0.0; 4] })
}

/// [`triangles_sse_for`], `None` when the edge functions alone reject every lane (most
/// blocks a ray reaches): the traversal then leaves the block without writing its
/// distances and barycentrics anywhere.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn block_hits_sse(b: &TriBlock, s: &BlockRay, t_min: f32, t_max: f32) -> Option<BlockHits> {
    use std::arch::x86_64::*;
    let [kx, ky, kz] = s.axes;
    // SAFETY: SSE2 is in the x86-64 baseline; every row holds 4 f32 and `prim` 4 u32.
    unsafe {
        let (ox, oy, oz) = (_mm_set1_ps(s.origin[0]), _mm_set1_ps(s.origin[1]), _mm_set1_ps(s.origin[2]));
        let (sx, sy, sz) = (_mm_set1_ps(s.shear[0]), _mm_set1_ps(s.shear[1]), _mm_set1_ps(s.shear[2]));
        // Per vertex: sheared x, y, and the depth `a[kz]` before scaling.
        let project = |v: usize| {
            let az = _mm_sub_ps(_mm_loadu_ps(b.p[v][kz].as_ptr()), oz);
            let x = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(b.p[v][kx].as_ptr()), ox), _mm_mul_ps(sx, az));
            let y = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(b.p[v][ky].as_ptr()), oy), _mm_mul_ps(sy, az));
            (x, y, az)
        };
        let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (project(0), project(1), project(2));
        let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
        let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
        let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
        let zero = _mm_setzero_ps();
        let sign = _mm_set1_ps(-0.0);
        let prim = _mm_loadu_si128(b.prim.as_ptr().cast());
        let empty_lanes = _mm_castsi128_ps(_mm_cmpeq_epi32(prim, _mm_set1_epi32(EMPTY as i32)));
        // Most blocks a ray reaches miss all four triangles, and the edge functions alone
        // say so: each lane's three are non-zero and not NaN (their product's magnitude is
        // above zero; one that underflows only sends its lane on to the full test) with
        // mixed signs (their sign bits differ). The distance, its error bound and the
        // division are then skipped. A lane that is not a triangle has three equal (zero)
        // vertices, so its edge functions are zero or NaN and it is never skipped.
        let nonzero = _mm_cmpgt_ps(_mm_andnot_ps(sign, _mm_mul_ps(_mm_mul_ps(u, v), w)), zero);
        let mixed = _mm_or_ps(_mm_xor_ps(u, v), _mm_xor_ps(u, w));
        if _mm_movemask_ps(_mm_or_ps(_mm_and_ps(nonzero, mixed), empty_lanes)) == 0xF {
            return None;
        }
        let undecided_edges = _mm_or_ps(
            _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)), _mm_cmpeq_ps(w, zero)),
            _mm_or_ps(_mm_cmpunord_ps(u, v), _mm_cmpunord_ps(w, w)),
        );
        // Where the edge functions are decided (non-zero, not NaN), mixed signs are
        // "outside". Only the sign bits of the masks below are read (`movemask`), and they
        // are combined bit by bit, so `mixed`'s sign bits serve as a mask.
        let outside = mixed;
        let empty = _mm_movemask_ps(empty_lanes) as u32;
        let other = _mm_movemask_ps(_mm_castsi128_ps(prim)) as u32 & !empty;
        let det = _mm_add_ps(_mm_add_ps(u, v), w);
        let (az, bz, cz) = (_mm_mul_ps(sz, az), _mm_mul_ps(sz, bz), _mm_mul_ps(sz, cz));
        let t_scaled = _mm_add_ps(_mm_add_ps(_mm_mul_ps(u, az), _mm_mul_ps(v, bz)), _mm_mul_ps(w, cz));
        // pbrt-v4's error bound on t, as `raylab_core::intersect::t_error_bound` writes it.
        let abs = |x: __m128| _mm_andnot_ps(sign, x);
        let max3 = |a: __m128, b: __m128, c: __m128| _mm_max_ps(_mm_max_ps(abs(a), abs(b)), abs(c));
        let (max_zt, max_xt, max_yt) = (max3(az, bz, cz), max3(ax, bx, cx), max3(ay, by, cy));
        let g = |n: u32| _mm_set1_ps(raylab_core::gamma(n));
        let delta_x = _mm_mul_ps(g(5), _mm_add_ps(max_xt, max_zt));
        let delta_y = _mm_mul_ps(g(5), _mm_add_ps(max_yt, max_zt));
        let delta_e = _mm_mul_ps(_mm_set1_ps(2.0), _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_mul_ps(g(2), max_xt), max_yt), _mm_mul_ps(delta_y, max_xt)), _mm_mul_ps(delta_x, max_yt)));
        if behind_for_sure(det, t_scaled, max_zt, delta_e, nonzero, mixed, empty_lanes) {
            return None;
        }
        let inv_det = _mm_div_ps(_mm_set1_ps(1.0), det);
        let t = _mm_mul_ps(t_scaled, inv_det);
        let max_e = max3(u, v, w);
        let delta_z = _mm_mul_ps(g(3), max_zt);
        let delta_t = _mm_mul_ps(
            _mm_mul_ps(_mm_set1_ps(3.0), _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_mul_ps(g(3), max_e), max_zt), _mm_mul_ps(delta_e, max_zt)), _mm_mul_ps(delta_z, max_e))),
            abs(inv_det),
        );
        // `abs < ∞` is false for NaN too.
        let inf = _mm_set1_ps(f32::INFINITY);
        let finite = _mm_and_ps(_mm_cmplt_ps(abs(t), inf), _mm_cmplt_ps(abs(delta_t), inf));
        let ahead = _mm_cmpgt_ps(t, delta_t);
        let behind = _mm_cmplt_ps(t, _mm_xor_ps(delta_t, sign));
        // Lanes the edge functions reject (as the scalar kernel: outside, or a zero determinant).
        let rejected = _mm_andnot_ps(undecided_edges, _mm_or_ps(outside, _mm_cmpeq_ps(det, zero)));
        let decided_t = _mm_and_ps(finite, _mm_or_ps(ahead, behind));
        let in_range = _mm_and_ps(_mm_cmpgt_ps(t, _mm_set1_ps(t_min)), _mm_cmple_ps(t, _mm_set1_ps(t_max)));
        let hit = _mm_andnot_ps(_mm_or_ps(undecided_edges, rejected), _mm_and_ps(_mm_and_ps(finite, ahead), in_range));
        let exact = _mm_or_ps(undecided_edges, _mm_andnot_ps(_mm_or_ps(rejected, decided_t), _mm_set1_ps(f32::from_bits(u32::MAX))));
        let mut out = BlockHits { hit: (_mm_movemask_ps(hit) as u32) & !empty & !other, exact: ((_mm_movemask_ps(exact) as u32) | other) & !empty, t: [0.0; 4], u: [0.0; 4], v: [0.0; 4] };
        _mm_storeu_ps(out.t.as_mut_ptr(), t);
        _mm_storeu_ps(out.u.as_mut_ptr(), _mm_mul_ps(v, inv_det));
        _mm_storeu_ps(out.v.as_mut_ptr(), _mm_mul_ps(w, inv_det));
        Some(out)
    }
}

/// Whether every lane of a block is settled without the distance's division and its full
/// error bound: empty, rejected by its edge functions (`nonzero` and `mixed`, see
/// [`block_hits_sse`]), or, with its edge functions all of one sign, certainly behind the
/// origin as [`block_hits_sse`] would decide it (`t < -δt`). A ray leaving a surface meets
/// the triangle it leaves this way in nearly every block it tests that is not a miss.
///
/// The test divides nothing. With `E = max(|u|, |v|, |w|) <= |det|·(1 + 3ε)` (one sign)
/// and `δz = γ₃·max_zt`, the bound is `δt = 3·(γ₃·E·max_zt + δe·max_zt + δz·E) / |det|
/// <= 3·max_zt·(2γ₃·|det| + δe) / |det|`, so `-t_scaled·sign(det) > 2·R` with
/// `R = 3·max_zt·(2γ₃·|det| + δe)` gives `t < -δt` with room for every rounding of
/// both computations. The magnitudes are kept within `[2⁻⁶³, 2⁶³]` so that neither
/// computation under- or overflows; other lanes go on to the full test.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn behind_for_sure(det: std::arch::x86_64::__m128, t_scaled: std::arch::x86_64::__m128, max_zt: std::arch::x86_64::__m128, delta_e: std::arch::x86_64::__m128, nonzero: std::arch::x86_64::__m128, mixed: std::arch::x86_64::__m128, empty: std::arch::x86_64::__m128) -> bool {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 is in the x86-64 baseline.
    unsafe {
        let sign = _mm_set1_ps(-0.0);
        let det_abs = _mm_andnot_ps(sign, det);
        let r = _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(3.0), max_zt), _mm_add_ps(_mm_mul_ps(_mm_set1_ps(2.0 * raylab_core::gamma(3)), det_abs), delta_e));
        // `t_scaled·sign(det)` (exact), below `-2R`.
        let toward = _mm_xor_ps(t_scaled, _mm_and_ps(det, sign));
        let behind = _mm_cmplt_ps(toward, _mm_mul_ps(_mm_set1_ps(-2.0), r));
        let (lo, hi) = (_mm_set1_ps(2f32.powi(-63)), _mm_set1_ps(2f32.powi(63)));
        let sane = _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(det_abs, lo), _mm_cmple_ps(det_abs, hi)), _mm_and_ps(_mm_cmpge_ps(r, lo), _mm_cmple_ps(_mm_andnot_ps(sign, t_scaled), hi)));
        // Lanes rejected by their edges, or decided (`nonzero`) of one sign and behind.
        let settled = _mm_and_ps(nonzero, _mm_or_ps(mixed, _mm_and_ps(behind, sane)));
        _mm_movemask_ps(_mm_or_ps(settled, empty)) == 0xF
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::wide::node::WideNode;
    use crate::wide::ray::ROBUST_FAR;
    use raylab_core::Ray;
    use raylab_core::{Aabb, Vec3};

    fn node8() -> WideNode<8> {
        let mut n = WideNode::<8>::EMPTY_NODE;
        n.set(0, &Aabb::new(Vec3::ZERO, Vec3::ONE), 10);
        // The ray below lies in this box's y = 0.5 face plane: a NaN slab, ignored.
        n.set(2, &Aabb::new(Vec3::new(2.0, 0.5, 0.0), Vec3::new(3.0, 0.7, 1.0)), 12);
        // Behind the origin.
        n.set(3, &Aabb::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::new(-2.0, 1.0, 1.0)), 13);
        // Beyond t_max = 10.
        n.set(5, &Aabb::new(Vec3::new(20.0, 0.0, 0.0), Vec3::new(21.0, 1.0, 1.0)), 15);
        n
    }

    #[test]
    fn hand_computed_slab_tests() {
        let ray = Ray::segment(Vec3::new(-1.0, 0.5, 0.5), Vec3::X, 0.0, 10.0);
        let r = RayBoxes::new(&ray);
        let n = node8();
        let mut t = [0.0; 8];
        // Lanes 0 (entry at x = 0: t = 1) and 2 (entry at x = 2: t = 3); the empty slots,
        // the box behind and the one beyond t_max are missed.
        assert_eq!(boxes_portable(&n, &r, ray.t_max, &mut t), 0b101);
        assert_eq!((t[0], t[2]), (1.0, 3.0));
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            let mut t8 = [0.0; 8];
            // SAFETY: AVX2 detected.
            assert_eq!(unsafe { boxes_avx2(&n, &r, ray.t_max, &mut t8) }, 0b101);
            assert_eq!(t8.map(f32::to_bits), t.map(f32::to_bits), "identical entry distances");
        }
        // Reversed direction: only the box behind, entered at t = 1 (x = -2).
        let back = Ray::segment(Vec3::new(-1.0, 0.5, 0.5), -Vec3::X, 0.0, 10.0);
        assert_eq!(boxes_portable(&n, &RayBoxes::new(&back), back.t_max, &mut t), 0b1000);
        assert_eq!(t[3], 1.0);
    }

    /// Integer order ([`RayBoxes::by_bits`]) enters the boxes the float order enters, at the
    /// same distances to the bit (and beyond them only its corner's, at t = 0), and the SIMD kernels agree with the portable one to the
    /// bit: random boxes (some flat), empty lanes, origins on box planes, `t_min` above
    /// zero and far limits cutting boxes.
    #[test]
    fn integer_order_matches_float_order() {
        let mut rng = raylab_core::Pcg32::new(11, 3);
        let mut f = |s: f32| (rng.next_f32() - 0.5) * s;
        let mut entered = 0;
        for k in 0..20000 {
            let mut n = WideNode::<8>::EMPTY_NODE;
            let boxes: Vec<Aabb> = (0..1 + k % 8).map(|l| {
                let lo = Vec3::new(f(4.0), f(4.0), f(4.0));
                let mut ext = Vec3::new(f(2.0).abs(), f(2.0).abs(), f(2.0).abs());
                ext[l % 3] *= if (k + l) % 5 == 0 { 0.0 } else { 1.0 };
                Aabb::new(lo, lo + ext)
            }).collect();
            for (l, b) in boxes.iter().enumerate() {
                n.set(l, b, l as u32);
            }
            let mut o = Vec3::new(f(8.0), f(8.0), f(8.0));
            if k % 3 == 0 {
                // On a plane of the first box.
                let a = k % 9 / 3;
                o[a] = if k % 2 == 0 { boxes[0].min[a] } else { boxes[0].max[a] };
            }
            // Aimed near a box's centre, so that most rays enter some.
            let aim = boxes[k % boxes.len()];
            let d = ((aim.min + aim.max) * 0.5 + Vec3::new(f(1.0), f(1.0), f(1.0)) - o).try_normalize().unwrap_or(Vec3::ONE.normalize());
            let ray = Ray::segment(o, d, if k % 4 == 0 { 0.5 } else { 0.0 }, if k % 5 == 0 { 2.0 + f(2.0) } else { f32::INFINITY });
            let r = RayBoxes::new(&ray);
            assert!(r.by_bits, "ray {k}");
            let float = RayBoxes { by_bits: false, ..r };
            let t_max = ray.t_max * ROBUST_FAR;
            let (mut tb, mut tf) = ([0.0f32; 8], [0.0f32; 8]);
            let mb = boxes_portable(&n, &r, t_max, &mut tb);
            let mf = boxes_portable(&n, &float, t_max, &mut tf);
            assert_eq!(mb & mf, mf, "ray {k}: a box float order enters is missed");
            for l in 0..8 {
                if mf & (1 << l) != 0 {
                    assert_eq!(tb[l].to_bits(), tf[l].to_bits(), "ray {k} lane {l}: entry distance");
                } else if mb & (1 << l) != 0 {
                    // The corner (`integer_order_enters_a_box_left_at_zero`).
                    assert_eq!(tb[l].to_bits(), 0, "ray {k} lane {l}: entered where float order misses");
                }
            }
            entered += mf.count_ones();
            #[cfg(target_arch = "x86_64")]
            {
                if std::is_x86_feature_detected!("avx2") {
                    let mut t8 = [0.0f32; 8];
                    // SAFETY: AVX2 detected.
                    assert_eq!(unsafe { boxes_avx2(&n, &r, t_max, &mut t8) }, mb, "ray {k}: AVX2");
                    assert_eq!(t8.map(f32::to_bits), tb.map(f32::to_bits), "ray {k}: AVX2 distances");
                }
                let mut n4 = WideNode::<4>::EMPTY_NODE;
                for (l, b) in boxes.iter().take(4).enumerate() {
                    n4.set(l, b, l as u32);
                }
                let (mut t4, mut tp) = ([0.0f32; 4], [0.0f32; 4]);
                let m4 = boxes_portable(&n4, &r, t_max, &mut tp);
                assert_eq!(m4, mb & 0xF, "ray {k}: four wide");
                assert_eq!(boxes_sse(&n4, &r, t_max, &mut t4), m4, "ray {k}: SSE2");
                assert_eq!(t4.map(f32::to_bits), tp.map(f32::to_bits), "ray {k}: SSE2 distances");
            }
        }
        assert!(entered > 5000, "too few boxes entered: {entered}");
    }

    /// Integer order's one corner: a ray starting on box `[0, 1]³`'s `x = 0` face, leaving it
    /// along −x (exit distance −0), from above it in y (exit distance −2). Float order misses
    /// the box; integer order enters it at t = 0, which costs a visit and changes no answer
    /// (hits need t > t_min = 0).
    #[test]
    fn integer_order_enters_a_box_left_at_zero() {
        let mut n = WideNode::<8>::EMPTY_NODE;
        n.set(0, &Aabb::new(Vec3::ZERO, Vec3::ONE), 0);
        let ray = Ray::new(Vec3::new(0.0, 2.0, 0.5), Vec3::new(-1.0, 0.5, 0.25));
        let r = RayBoxes::new(&ray);
        let mut t = [1.0f32; 8];
        assert_eq!(boxes_portable(&n, &RayBoxes { by_bits: false, ..r }, f32::INFINITY, &mut t), 0);
        assert_eq!(boxes_portable(&n, &r, f32::INFINITY, &mut t), 1);
        assert_eq!(t[0].to_bits(), 0.0f32.to_bits());
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: AVX2 detected.
            assert_eq!(unsafe { boxes_avx2(&n, &r, f32::INFINITY, &mut t) }, 1);
        }
    }

    #[test]
    fn four_wide_sse_matches_portable() {
        let mut n = WideNode::<4>::EMPTY_NODE;
        n.set(0, &Aabb::new(Vec3::ZERO, Vec3::ONE), 1);
        n.set(1, &Aabb::new(Vec3::new(0.0, 2.0, 0.0), Vec3::new(1.0, 3.0, 1.0)), 2);
        let ray = Ray::new(Vec3::new(0.5, -1.0, 0.5), Vec3::new(0.0, 1.0, 0.0));
        let r = RayBoxes::new(&ray);
        let mut t = [0.0; 4];
        assert_eq!(boxes_portable(&n, &r, f32::INFINITY, &mut t), 0b11);
        assert_eq!((t[0], t[1]), (1.0, 3.0));
        #[cfg(target_arch = "x86_64")]
        {
            let mut t4 = [0.0; 4];
            assert_eq!(boxes_sse(&n, &r, f32::INFINITY, &mut t4), 0b11);
            assert_eq!(t4.map(f32::to_bits), t.map(f32::to_bits));
        }
    }

    #[test]
    fn triangle_filter_keeps_every_hit() {
        let mut rng = raylab_core::Pcg32::new(5, 1);
        let mut b = TriBlock::EMPTY_BLOCK;
        let tris: Vec<[Vec3; 3]> = (0..3).map(|_| [0, 1, 2].map(|_| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5)).collect();
        for (l, v) in tris.iter().enumerate() {
            b.set_triangle(l, l as u32, *v);
        }
        let mut kept = 0;
        for _ in 0..5000 {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - 2.0;
            let ray = Ray::new(o, (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5 - o).normalize());
            let s = ShearedRay::new(&ray);
            let m = triangle_candidates(&b, &s);
            assert_eq!(m & 0b1000, 0, "the empty lane is never a candidate");
            for (l, v) in tris.iter().enumerate() {
                if raylab_core::intersect::triangle(&ray, v[0], v[1], v[2]).is_some() {
                    assert_ne!(m & (1 << l), 0, "a hit was filtered out");
                    kept += 1;
                }
            }
        }
        assert!(kept > 100, "too few hits to test the filter: {kept}");
    }

    /// A block of `lanes` triangles for kernel tests, from `r(scale)` (random points at that
    /// scale): by `k`, some lanes are all zero and some have two equal vertices (the
    /// scalar kernel's zero edge functions), the rest random.
    pub(in crate::wide) fn random_block(k: usize, lanes: usize, scale: f32, r: &mut impl FnMut(f32) -> Vec3) -> TriBlock {
        let mut b = TriBlock::EMPTY_BLOCK;
        for l in 0..lanes {
            let v = match (k + l) % 6 {
                0 => [Vec3::ZERO; 3],
                1 => {
                    let p = r(scale);
                    [p, p, r(scale)]
                }
                _ => [r(scale), r(scale), r(scale)],
            };
            b.set_triangle(l, l as u32, v);
        }
        b
    }

    /// Rays leaving a triangle, or arriving at it, from a few ulps to a thousandth of its
    /// size off its plane (what `behind_for_sure` settles without the division): the
    /// four-wide kernel still gives the scalar kernel's answer lane by lane, the triangle
    /// behind is skipped, and the tiny hits ahead are found.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn rays_leaving_or_reaching_a_triangle_get_the_scalar_answers() {
        let mut rng = raylab_core::Pcg32::new(17, 5);
        let mut r = |scale: f32| Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5) * scale;
        let (mut near_hits, mut behind, mut skipped) = (0, 0, 0);
        for k in 0..20000 {
            let scale = [1.0, 1e-4, 1e4, 1e-12][k % 4];
            let mut b = random_block(k, 1 + k % 4, scale, &mut r);
            let (p0, p1, p2) = (r(scale), r(scale), r(scale));
            b.set_triangle(0, 0, [p0, p1, p2]);
            let Some(n) = (p1 - p0).cross(p2 - p0).try_normalize() else { continue };
            let inside = p0 + 0.2 * (p1 - p0) + 0.3 * (p2 - p0);
            // Off the plane by 2^-(4..24) of its size, on either side, leaving or arriving.
            let h = scale * 2f32.powi(-4 - (k / 4 % 21) as i32) * if k % 2 == 0 { 1.0 } else { -1.0 };
            let o = inside + n * h;
            let leave = if k % 3 == 0 { -1.0 } else { 1.0 };
            let d = (n * (h.signum() * leave) + r(1.5)).try_normalize().unwrap_or(n);
            let ray = Ray::new(o, d);
            let s = ShearedRay::new(&ray);
            let h4 = triangles_sse(&b, &s, 0.0, f32::INFINITY);
            if h4.hit == 0 && h4.exact == 0 {
                skipped += 1;
            }
            for l in 0..4 {
                let bit = 1 << l;
                if b.prim[l] == EMPTY || h4.exact & bit != 0 {
                    continue;
                }
                let scalar = s.triangle(0.0, f32::INFINITY, b.vertex(l, 0), b.vertex(l, 1), b.vertex(l, 2));
                let simd = (h4.hit & bit != 0).then(|| (h4.t[l], h4.u[l], h4.v[l]));
                assert_eq!(simd.map(|(t, u, v)| [t, u, v].map(f32::to_bits)), scalar.map(|(t, u, v)| [t, u, v].map(f32::to_bits)), "block {k} lane {l}");
                if l == 0 {
                    // Leaving: moving further from the plane than the origin is.
                    let leaving = n.dot(d) * h > 0.0;
                    match scalar {
                        Some((t, _, _)) if t < 1e-3 * scale => near_hits += 1,
                        None if leaving => behind += 1,
                        _ => {}
                    }
                }
            }
        }
        assert!(near_hits > 2000 && behind > 2000 && skipped > 2000, "too few cases: {near_hits} tiny hits, {behind} triangles behind, {skipped} blocks settled");
    }

    /// The four-wide kernel decides each lane exactly as the scalar kernel does (same `t`
    /// and barycentrics to the bit) or hands it to the scalar kernel: on random triangles,
    /// degenerate ones (zero area, a vertex at the origin: zero edge functions), tiny,
    /// huge and overflowing coordinates, rays starting on the triangles (t within the error
    /// bound), and `t` ranges that cut hits off.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn sse_triangle_kernel_matches_the_scalar_kernel() {
        let mut rng = raylab_core::Pcg32::new(7, 1);
        let mut r = |scale: f32| Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5) * scale;
        let (mut hits, mut exact) = (0, 0);
        for k in 0..40000 {
            let scale = [1.0, 1e-30, 1e30, 3e38, 1e6][(k / 4) % 5];
            let lanes = k % 4 + 1;
            let mut b = random_block(k, lanes, scale, &mut r);
            if k % 7 == 0 {
                // Not a triangle: its vertices are zero, as the collapse leaves them.
                b.set_triangle(0, 3 | TriBlock::OTHER, [Vec3::ZERO; 3]);
            }
            // Origins: the origin, random, or on a lane's triangle (t ≈ 0).
            let o = match k % 3 {
                0 => Vec3::ZERO,
                1 => r(2.0 * scale),
                _ => {
                    let (p0, p1, p2) = (b.vertex(lanes - 1, 0), b.vertex(lanes - 1, 1), b.vertex(lanes - 1, 2));
                    p0 + 0.3 * (p1 - p0) + 0.3 * (p2 - p0)
                }
            };
            let target = b.vertex(k % lanes, 0) / 3.0 + b.vertex(k % lanes, 1) / 3.0 + b.vertex(k % lanes, 2) / 3.0 + r(0.1 * scale);
            let d = (target - o).try_normalize().unwrap_or(Vec3::Z);
            let ray = Ray::new(o, if k % 11 == 0 { -d } else { d });
            let s = ShearedRay::new(&ray);
            let (t_min, t_max) = if k % 5 == 0 { (0.0, 0.5 * scale) } else { (0.0, f32::INFINITY) };
            let h = triangles_sse(&b, &s, t_min, t_max);
            assert_eq!(h.hit & h.exact, 0, "block {k}: a lane both decided and not");
            for l in 0..4 {
                let bit = 1 << l;
                let p = b.prim[l];
                if p == EMPTY {
                    assert_eq!((h.hit | h.exact) & bit, 0, "block {k}: empty lane {l}");
                    continue;
                }
                if p & TriBlock::OTHER != 0 {
                    assert_ne!(h.exact & bit, 0, "block {k}: a non-triangle lane {l} must go to its own test");
                    continue;
                }
                let scalar = s.triangle(t_min, t_max, b.vertex(l, 0), b.vertex(l, 1), b.vertex(l, 2));
                if h.exact & bit != 0 {
                    exact += 1;
                    continue;
                }
                let simd = (h.hit & bit != 0).then(|| (h.t[l], h.u[l], h.v[l]));
                assert_eq!(simd.map(|(t, u, v)| [t, u, v].map(f32::to_bits)), scalar.map(|(t, u, v)| [t, u, v].map(f32::to_bits)), "block {k} lane {l}");
                hits += usize::from(simd.is_some());
            }
        }
        assert!(hits > 3000 && exact > 100, "too few cases of each kind: {hits} hits, {exact} left to the scalar kernel");
    }
}
