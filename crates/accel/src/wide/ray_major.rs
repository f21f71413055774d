//! Closest hits of a 16-ray packet with AVX-512, ray-major as Embree's `rtcIntersect16`:
//! ray `r` lives in lane `r` of every 512-bit register, and a node's child box (or a
//! leaf's triangle) is broadcast and tested against all sixteen rays at once. The
//! child-major path (`packet.rs`) runs each ray's 8-wide box test in turn instead, and
//! transposes the answers into per-child ray masks.
//!
//! Each lane does the single-ray kernels' IEEE operations in the same order (the slab test
//! of [`slabs_avx2`](super::kernels::slabs_avx2), the watertight test of
//! [`triangles_sse`](super::kernels::triangles_sse)), and hits are kept as the least
//! `(t, prim)` as in [`wins`](super::traverse::wins), so every ray gets exactly its
//! single-ray answer. A stack entry carries each ray's entry distance into the child
//! (infinity for rays that did not enter it), so a pop drops exactly the rays whose hit so
//! far lies nearer, ray by ray.
//!
//! A node is first tested against the packet's frustum (one 8-wide test bounding all
//! sixteen rays' slab distances, as Embree's coherent traversal does), and only the
//! children it keeps are tested ray by ray in the sixteen lanes; they are visited in the
//! order of the frustum's entry distances. Pushed children are prefetched.
//!
//! It needs the packet's rays to share their direction signs (the box rows they read) and
//! their shear axes (the triangle coordinates they read): camera tiles nearly always do.
//! [`closest`] declines other packets, and the caller takes the child-major path.

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use raylab_core::intersect::ShearedRay;
use raylab_core::{gamma, Ray};

use super::kernels::{BlockRay, ROBUST_FAR};
use super::node::{is_leaf, Layout, TriBlock, WideNode, EMPTY};
use super::packet::{prefetch, PACKET};
use super::traverse::{block_closest, exact_lane, insert_sorted, leaf_slice, occupied, wins, STACK};
use super::WideBvh;
use crate::{Counters, Hit, Primitives};

/// Sixteen lanes, aligned for 512-bit loads and stores.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Lanes([f32; PACKET]);

/// The packet's per-ray constants, one lane per ray, and what its rays share.
struct Packet {
    origin: [__m512; 3],
    inv: [__m512; 3],
    inv_far: [__m512; 3],
    t_min: __m512,
    /// Shear `d[kx]/d[kz]`, `d[ky]/d[kz]` and scale `1/d[kz]`.
    shear: [__m512; 3],
    /// `RayBoxes::near` and `far` of every ray.
    near_rows: [usize; 3],
    far_rows: [usize; 3],
    /// `(kx, ky, kz)` of every ray's `ShearedRay`.
    axes: (usize, usize, usize),
    /// `origin` and `shear` stored lane by lane (6 rows).
    each: [Lanes; 6],
    /// The packet's frustum, when its constants are finite.
    frustum: Option<Frustum>,
}

/// What bounds every ray's slab distances, so that one 8-wide test culls the children no
/// ray of the packet enters (Embree's coherent traversal does the same). IEEE operations
/// are monotone, so the slab arithmetic on the extreme origin and inverse of each axis
/// bounds each ray's entry distance from below and exit distance from above; with finite
/// constants no NaN arises.
pub(super) struct Frustum {
    /// Per axis, the origin giving the least near-plane difference `bound - origin` for
    /// rays along `+axis` (the greatest origin) and the greatest for rays along `-axis`.
    pub(super) near_origin: [f32; 3],
    /// The other extreme, for the far planes.
    pub(super) far_origin: [f32; 3],
    /// Per axis, the least and greatest inverse direction, and the same of `inv_far`.
    pub(super) inv: [[f32; 2]; 3],
    pub(super) inv_far: [[f32; 2]; 3],
    /// The least `t_min`.
    pub(super) t_min: f32,
}

impl Packet {
    /// Ray `r`'s `ShearedRay`.
    fn sheared(&self, r: usize) -> ShearedRay {
        let e = |k: usize| self.each[k].0[r];
        let (kx, ky, kz) = self.axes;
        ShearedRay { origin: raylab_core::Vec3::new(e(0), e(1), e(2)), kx, ky, kz, sx: e(3), sy: e(4), sz: e(5) }
    }
}

impl Packet {
    /// The constants of `rays` (1 to [`PACKET`]; lanes past their count repeat the last
    /// ray), computed as `RayBoxes::new` and `ShearedRay::new` do ray by ray, and their
    /// `t_max`; `None` unless they share box rows and shear axes.
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    fn new(rays: &[Ray]) -> Option<(Packet, __m512)> {
        let n = rays.len();
        // The rays' origins, directions and intervals, one lane per ray: eight loads of two
        // rays each, transposed (eight 16-lane gathers cost more). Lanes past `n`
        // repeat the last ray and are never active.
        let padded: [Ray; PACKET];
        let src = if n == PACKET {
            rays.as_ptr()
        } else {
            padded = std::array::from_fn(|r| rays[r.min(n - 1)]);
            padded.as_ptr()
        };
        // SAFETY: `src` points to 16 rays of 8 f32 each (`RAY_F32`), two per 64-byte load.
        let fields = transpose(std::array::from_fn(|k| unsafe { _mm512_loadu_ps(src.cast::<f32>().add(16 * k)) }));
        let field = |offset: usize| fields[offset / 4];
        let (o, d) = (std::mem::offset_of!(Ray, origin), std::mem::offset_of!(Ray, dir));
        let (origin, dir) = ([0, 4, 8].map(|a| field(o + a)), [0, 4, 8].map(|a| field(d + a)));
        let (t_min, t_max) = (field(std::mem::offset_of!(Ray, t_min)), field(std::mem::offset_of!(Ray, t_max)));
        let zero = _mm512_setzero_ps();
        let one = _mm512_set1_ps(1.0);
        // `RayBoxes::new` lane by lane: the near rows must agree.
        let inv = dir.map(|d| _mm512_div_ps(one, _mm512_add_ps(d, zero)));
        let negative = inv.map(|i| _mm512_cmp_ps_mask::<_CMP_LT_OQ>(i, zero));
        if negative.iter().any(|&m| m != 0 && m != 0xFFFF) {
            return None;
        }
        let near_rows = [0, 1, 2].map(|a| if negative[a] != 0 { 3 + a } else { a });
        let far_rows = [0, 1, 2].map(|a| if negative[a] != 0 { a } else { 3 + a });
        // `ShearedRay::new` lane by lane: the axes must agree.
        #[allow(clippy::redundant_closure)] // a `#[target_feature]` fn is not `FnMut`
        let ad = dir.map(|d| _mm512_abs_ps(d));
        let gt = |a: usize, b: usize| _mm512_cmp_ps_mask::<_CMP_GT_OQ>(ad[a], ad[b]);
        let (x0, z0, yz) = (gt(0, 1), gt(0, 2), gt(1, 2));
        let (along_x, along_y) = (x0 & z0, !x0 & yz);
        let kz = match (along_x, along_y) {
            (0xFFFF, _) => 0,
            (_, 0xFFFF) => 1,
            (0, 0) => 2,
            _ => return None,
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        match _mm512_cmp_ps_mask::<_CMP_LT_OQ>(dir[kz], zero) {
            0 => {}
            0xFFFF => std::mem::swap(&mut kx, &mut ky),
            _ => return None,
        }
        // `1/d[kz]` is `inv[kz]` (`1/(d + 0)`) unless `d[kz]` is `-0`: a zero direction,
        // left to the child-major path.
        if _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(dir[kz], zero) != 0 {
            return None;
        }
        let robust_far = _mm512_set1_ps(ROBUST_FAR);
        let shear = [_mm512_div_ps(dir[kx], dir[kz]), _mm512_div_ps(dir[ky], dir[kz]), inv[kz]];
        let inv_far = inv.map(|i| _mm512_mul_ps(i, robust_far));
        // The same constants ray by ray, for leaves that one ray reaches.
        let mut each = [Lanes([0.0; PACKET]); 6];
        for (k, x) in origin.iter().chain(&shear).enumerate() {
            // SAFETY: `Lanes` is 64-byte aligned.
            unsafe { _mm512_store_ps(each[k].0.as_mut_ptr(), *x) };
        }
        let inf = _mm512_set1_ps(f32::INFINITY);
        let finite = |x: &__m512| _mm512_cmp_ps_mask::<_CMP_LT_OQ>(_mm512_abs_ps(*x), inf) == 0xFFFF;
        let frustum = (origin.iter().chain(&inv).chain(&inv_far).all(finite) && finite(&t_min)).then(|| {
            // Thirteen reductions at once: maxima as negated minima of the negated lanes
            // (exact for finite values).
            let neg = |x: __m512| _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(x), _mm512_set1_epi32(i32::MIN)));
            let [o0, o1, o2] = origin;
            let [i0, i1, i2] = inv;
            let least = least_of_each([o0, o1, o2, neg(o0), neg(o1), neg(o2), i0, i1, i2, neg(i0), neg(i1), neg(i2), t_min, t_min, t_min, t_min]);
            let (lo, hi) = ([least[0], least[1], least[2]], [-least[3], -least[4], -least[5]]);
            let along = |a: usize, pos: [f32; 3], neg: [f32; 3]| if negative[a] == 0 { pos[a] } else { neg[a] };
            let inv = [0, 1, 2].map(|a| [least[6 + a], -least[9 + a]]);
            Frustum {
                near_origin: [0, 1, 2].map(|a| along(a, hi, lo)),
                far_origin: [0, 1, 2].map(|a| along(a, lo, hi)),
                inv,
                // Rounding is monotone: the extremes of `inv · ROBUST_FAR` are those of `inv`
                // times it, as each lane computes it.
                inv_far: inv.map(|[l, h]| [l * ROBUST_FAR, h * ROBUST_FAR]),
                t_min: least[12],
            }
        });
        Some((Packet { origin, inv, inv_far, t_min, shear, near_rows, far_rows, axes: (kx, ky, kz), each, frustum }, t_max))
    }
}

/// Floats per [`Ray`]: a packet's rays load as 64-byte pairs.
const RAY_F32: usize = 8;
const _: () = assert!(std::mem::size_of::<Ray>() == 4 * RAY_F32);

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
    let mut out = Lanes([0.0; PACKET]);
    // SAFETY: `Lanes` is 64-byte aligned.
    unsafe { _mm512_store_ps(out.0.as_mut_ptr(), least(v[0], v[1])) };
    out.0
}

/// What each ray has found so far: its `t_max` (the best hit's distance once it has one),
/// the best primitive (`u32::MAX` for none) and its barycentrics.
struct Best {
    t: __m512,
    prim: __m512i,
    u: __m512,
    v: __m512,
}

/// [`Best`] stored lane by lane.
struct BestLanes {
    t: Lanes,
    u: Lanes,
    v: Lanes,
    prim: [u32; PACKET],
}

impl Best {
    #[target_feature(enable = "avx512f")]
    fn store(&self) -> BestLanes {
        let mut l = BestLanes { t: Lanes([0.0; PACKET]), u: Lanes([0.0; PACKET]), v: Lanes([0.0; PACKET]), prim: [0; PACKET] };
        // SAFETY: `Lanes` is 64-byte aligned, and every array holds 16 lanes of 4 bytes.
        unsafe {
            _mm512_store_ps(l.t.0.as_mut_ptr(), self.t);
            _mm512_store_ps(l.u.0.as_mut_ptr(), self.u);
            _mm512_store_ps(l.v.0.as_mut_ptr(), self.v);
            _mm512_storeu_si512(l.prim.as_mut_ptr().cast(), self.prim);
        }
        l
    }

    #[target_feature(enable = "avx512f")]
    fn load(l: &BestLanes) -> Best {
        // SAFETY: as in `store`.
        unsafe { Best { t: _mm512_load_ps(l.t.0.as_ptr()), u: _mm512_load_ps(l.u.0.as_ptr()), v: _mm512_load_ps(l.v.0.as_ptr()), prim: _mm512_loadu_si512(l.prim.as_ptr().cast()) } }
    }

    /// Ray `r`'s hit so far.
    fn hit(l: &BestLanes, r: usize) -> Option<Hit> {
        (l.prim[r] != u32::MAX).then(|| Hit { t: l.t.0[r], prim: l.prim[r], u: l.u.0[r], v: l.v.0[r] })
    }
}

/// Closest hits of `rays` (1 to [`PACKET`]) into `out` (as long as `rays`); `false`, with
/// `out` and `c` untouched, for a packet whose rays do not share their box rows and shear
/// axes. Counting (`COUNT`) charges as the child-major path does: each node once per
/// active ray, each block's occupied lanes once per ray tested against it.
///
/// # Safety
/// The CPU must support AVX-512F and VL, AVX2, BMI1 and BMI2.
#[target_feature(enable = "avx2,avx512f,avx512vl,bmi1,bmi2")]
pub(super) unsafe fn closest<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool>(bvh: &WideBvh<W, N>, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) -> bool {
    let n = rays.len();
    debug_assert!((1..=PACKET).contains(&n) && out.len() == n);
    let Some((p, t_max)) = Packet::new(rays) else { return false };
    out.fill(None);
    if COUNT {
        c.rays += n as u64;
    }
    if bvh.root == EMPTY {
        return true;
    }
    let (near_rows, far_rows, (kx, ky, kz)) = (p.near_rows, p.far_rows, p.axes);
    let zero = _mm512_setzero_ps();
    let mut best = Best { t: t_max, prim: _mm512_set1_epi32(-1), u: zero, v: zero };
    let mut far = _mm512_mul_ps(best.t, _mm512_set1_ps(ROBUST_FAR));
    // Every ray's `far`, for the frustum.
    let mut far_max = _mm512_reduce_max_ps(far);
    let mut stack_node = [const { MaybeUninit::<u32>::uninit() }; STACK];
    let mut stack_t = [const { MaybeUninit::<Lanes>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = bvh.root;
    // Each ray's entry distance into `cur`: infinity for rays not in it.
    let all: __mmask16 = if n == PACKET { 0xFFFF } else { (1 << n) - 1 };
    let mut cur_t = _mm512_mask_blend_ps(all, _mm512_set1_ps(f32::INFINITY), p.t_min);
    'walk: loop {
        // Rays still in this subtree: entered it, and their hit so far is not nearer.
        let active = _mm512_cmp_ps_mask::<_CMP_LE_OQ>(cur_t, far) & all;
        if active != 0 {
            if COUNT {
                c.nodes_visited += u64::from(active.count_ones());
            }
            if is_leaf(cur) {
                let blocks = leaf_slice(bvh, cur);
                if COUNT {
                    c.prim_tests += blocks.iter().map(occupied).sum::<u64>() * u64::from(active.count_ones());
                }
                if active.count_ones() <= FEW_IN_LEAF {
                    few_in_leaf(blocks, prims, rays, &p, active, &mut best);
                } else {
                    for b in blocks {
                        block(b, prims, rays, &p, (kx, ky, kz), active, &mut best);
                    }
                }
                far = _mm512_mul_ps(best.t, _mm512_set1_ps(ROBUST_FAR));
                far_max = _mm512_reduce_max_ps(far);
            } else {
                // Children any ray entered, the nearest first; the others wait on the
                // stack with each ray's entry distance.
                let lane_bits = W as u32 - 1;
                let mut entry = [const { MaybeUninit::<Lanes>::uninit() }; W];
                let mut keys = [0u32; W];
                let mut k = 0;
                bvh.nodes[cur as usize].with_decoded(|node| {
                    // SAFETY: `W == 8` (the caller's check), so the types are the same.
                    let node8 = unsafe { &*(node as *const WideNode<W>).cast::<WideNode<8>>() };
                    // Children are ordered by the frustum's entry distance (a packet of
                    // copies of one ray walks as that ray does alone), else by their rays'
                    // least entry distance.
                    let mut order = [0.0f32; 8];
                    let mut candidates = match &p.frustum {
                        Some(f) => {
                            let (m, t0) = frustum_slabs(node8, f, near_rows, far_rows, far_max);
                            // SAFETY: `order` holds 8 f32.
                            unsafe { _mm256_storeu_ps(order.as_mut_ptr(), t0) };
                            m
                        }
                        None => (1 << W) - 1,
                    };
                    while candidates != 0 {
                        let l = candidates.trailing_zeros() as usize;
                        candidates &= candidates - 1;
                        if node.child[l] == EMPTY {
                            continue;
                        }
                        let (hit, t0) = slabs(node, l, &p, near_rows, far_rows, far, active);
                        if hit == 0 {
                            continue;
                        }
                        // SAFETY: as above; `Lanes` is 64-byte aligned.
                        let key = unsafe {
                            _mm512_store_ps(entry[l].as_mut_ptr().cast(), _mm512_mask_blend_ps(hit, _mm512_set1_ps(f32::INFINITY), t0));
                            let least = if p.frustum.is_some() { order[l] } else { _mm512_mask_reduce_min_ps(hit, t0) };
                            (least.to_bits() & !lane_bits) | l as u32
                        };
                        insert_sorted(&mut keys, &mut k, key);
                    }
                });
                if k > 0 {
                    let node = &bvh.nodes[cur as usize];
                    for &key in keys[1..k].iter().rev() {
                        let l = (key & lane_bits) as usize;
                        prefetch(bvh, node.child(l));
                        stack_node[sp] = MaybeUninit::new(node.child(l));
                        stack_t[sp] = entry[l];
                        sp += 1;
                    }
                    let l = (keys[0] & lane_bits) as usize;
                    cur = node.child(l);
                    // SAFETY: the entries of entered lanes were stored above; `Lanes` is aligned.
                    cur_t = unsafe { _mm512_load_ps(entry[l].as_ptr().cast()) };
                    continue 'walk;
                }
            }
        }
        if sp == 0 {
            break;
        }
        sp -= 1;
        // SAFETY: entries below `sp` were written by the pushes above; `Lanes` is aligned.
        (cur, cur_t) = unsafe { (stack_node[sp].assume_init(), _mm512_load_ps(stack_t[sp].assume_init_ref().0.as_ptr())) };
    }
    let lanes = best.store();
    for (r, o) in out.iter_mut().enumerate() {
        *o = Best::hit(&lanes, r);
    }
    true
}

/// Leaves that this many rays or fewer reach are tested ray by ray (each ray's four-wide
/// triangle test): sixteen lanes for one ray cost more. Nodes are always tested in sixteen
/// lanes: after the frustum test that is cheaper than ray by ray even for two rays.
pub(super) const FEW_IN_LEAF: u32 = 1;

/// The blocks of a leaf against the `active` rays one at a time, with the single-ray
/// block test, from and into their best hits so far.
#[inline]
#[target_feature(enable = "avx2,avx512f,avx512vl,bmi1,bmi2")]
fn few_in_leaf<P: Primitives + ?Sized>(blocks: &[TriBlock], prims: &P, rays: &[Ray], p: &Packet, active: __mmask16, best: &mut Best) {
    let mut lanes = best.store();
    let mut m = active;
    while m != 0 {
        let r = m.trailing_zeros() as usize;
        m &= m - 1;
        let mut hit = Best::hit(&lanes, r);
        let mut ray = Ray { t_max: lanes.t.0[r], ..rays[r] };
        let s = p.sheared(r);
        for b in blocks {
            block_closest::<P, true>(b, prims, &s, &BlockRay::new(&s), &mut ray, &mut hit);
        }
        if let Some(h) = hit {
            (lanes.t.0[r], lanes.prim[r], lanes.u.0[r], lanes.v.0[r]) = (h.t, h.prim, h.u, h.v);
        }
    }
    *best = Best::load(&lanes);
}

/// Child `l` of `node` against the `active` rays: the rays entering it (within each ray's
/// `far` limit) and their entry distances, as [`slabs_avx2`](super::kernels::slabs_avx2)
/// computes them for each ray.
#[inline]
#[target_feature(enable = "avx2,avx512f,avx512vl")]
fn slabs<const W: usize>(node: &WideNode<W>, l: usize, p: &Packet, near_rows: [usize; 3], far_rows: [usize; 3], far: __m512, active: __mmask16) -> (__mmask16, __m512) {
    let mut t0 = p.t_min;
    let mut t1 = far;
    for a in 0..3 {
        let lo = _mm512_set1_ps(node.bounds[near_rows[a]][l]);
        let hi = _mm512_set1_ps(node.bounds[far_rows[a]][l]);
        let near = _mm512_mul_ps(_mm512_sub_ps(lo, p.origin[a]), p.inv[a]);
        let far = _mm512_mul_ps(_mm512_sub_ps(hi, p.origin[a]), p.inv_far[a]);
        // As in the single-ray kernel: `max(a, b)` returns `b` when either is NaN.
        t0 = _mm512_max_ps(near, t0);
        t1 = _mm512_min_ps(far, t1);
    }
    (_mm512_mask_cmp_ps_mask::<_CMP_LE_OQ>(active, t0, t1), t0)
}

/// The children of `node` that some ray of the packet may enter (a superset of those any
/// ray's [`slabs`] enters, since `far` bounds every ray's limit) and a lower bound of their
/// rays' entry distances. AVX2 alone: the 8-ray packets of `ray_major_avx2.rs` use it too.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn frustum_slabs(node: &WideNode<8>, f: &Frustum, near_rows: [usize; 3], far_rows: [usize; 3], far: f32) -> (u32, __m256) {
    let mut t0 = _mm256_set1_ps(f.t_min);
    let mut t1 = _mm256_set1_ps(far);
    let set = _mm256_set1_ps;
    for a in 0..3 {
        // SAFETY: a row holds 8 f32.
        let (lo, hi) = unsafe { (_mm256_loadu_ps(node.bounds[near_rows[a]].as_ptr()), _mm256_loadu_ps(node.bounds[far_rows[a]].as_ptr())) };
        let (dn, df) = (_mm256_sub_ps(lo, set(f.near_origin[a])), _mm256_sub_ps(hi, set(f.far_origin[a])));
        let near = _mm256_min_ps(_mm256_mul_ps(dn, set(f.inv[a][0])), _mm256_mul_ps(dn, set(f.inv[a][1])));
        let far = _mm256_max_ps(_mm256_mul_ps(df, set(f.inv_far[a][0])), _mm256_mul_ps(df, set(f.inv_far[a][1])));
        t0 = _mm256_max_ps(near, t0);
        t1 = _mm256_min_ps(far, t1);
    }
    (_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32, t0)
}

/// The triangles of block `b` against the `active` rays, updating each ray's best hit; a
/// lane the SIMD arithmetic cannot decide, or that is not a triangle, goes through the
/// exact scalar kernel ray by ray, as in single-ray traversal.
#[inline]
#[target_feature(enable = "avx2,avx512f,avx512vl,bmi1,bmi2")]
#[allow(clippy::too_many_arguments)]
fn block<P: Primitives + ?Sized>(b: &TriBlock, prims: &P, rays: &[Ray], p: &Packet, (kx, ky, kz): (usize, usize, usize), active: __mmask16, best: &mut Best) {
    for j in 0..4 {
        let prim = b.prim[j];
        if prim == EMPTY {
            continue;
        }
        let (hit, exact, t, u, v) = if prim & TriBlock::OTHER != 0 { (0, active, _mm512_setzero_ps(), _mm512_setzero_ps(), _mm512_setzero_ps()) } else { triangle(b, j, p, (kx, ky, kz), active, best.t) };
        if hit != 0 {
            keep(best, hit, t, u, v, prim);
        }
        let mut m = exact;
        while m != 0 {
            let r = m.trailing_zeros() as usize;
            m &= m - 1;
            let so_far = best.store();
            let ray = Ray { t_max: so_far.t.0[r], ..rays[r] };
            let id = prim & !TriBlock::OTHER;
            let so_far = Best::hit(&so_far, r);
            if let Some(x) = exact_lane(b, j, prims, &ShearedRay::new(&ray), &ray).filter(|x| x.t <= ray.t_max && wins(x.t, id, &so_far)) {
                keep(best, 1 << r, _mm512_set1_ps(x.t), _mm512_set1_ps(x.u), _mm512_set1_ps(x.v), id);
            }
        }
    }
}

/// Makes `(t, prim)` the best hit of the rays in `hit` where it wins: nearer, or as near
/// and a lower primitive ([`wins`](super::traverse::wins)).
#[inline]
#[target_feature(enable = "avx2,avx512f,avx512vl")]
fn keep(best: &mut Best, hit: __mmask16, t: __m512, u: __m512, v: __m512, prim: u32) {
    let id = _mm512_set1_epi32(prim as i32);
    let nearer = _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(hit, t, best.t);
    let tie = _mm512_mask_cmp_ps_mask::<_CMP_EQ_OQ>(hit, t, best.t) & _mm512_cmplt_epu32_mask(id, best.prim);
    let win = nearer | tie;
    best.t = _mm512_mask_blend_ps(win, best.t, t);
    best.u = _mm512_mask_blend_ps(win, best.u, u);
    best.v = _mm512_mask_blend_ps(win, best.v, v);
    best.prim = _mm512_mask_blend_epi32(win, best.prim, id);
}

/// Triangle `j` of block `b` against the `active` rays: [`triangles_sse`]'s operations
/// for one triangle and sixteen rays. Returns the rays hitting it within `(t_min, t_max]`
/// with `t` and barycentrics, and the rays left to the exact scalar kernel.
///
/// [`triangles_sse`]: super::kernels::triangles_sse
#[inline]
#[target_feature(enable = "avx2,avx512f,avx512vl")]
#[allow(clippy::type_complexity)]
fn triangle(b: &TriBlock, j: usize, p: &Packet, (kx, ky, kz): (usize, usize, usize), active: __mmask16, t_max: __m512) -> (__mmask16, __mmask16, __m512, __m512, __m512) {
    let [sx, sy, sz] = p.shear;
    let (ox, oy, oz) = (p.origin[kx], p.origin[ky], p.origin[kz]);
    let project = |v: usize| {
        let az = _mm512_sub_ps(_mm512_set1_ps(b.p[v][kz][j]), oz);
        let x = _mm512_sub_ps(_mm512_sub_ps(_mm512_set1_ps(b.p[v][kx][j]), ox), _mm512_mul_ps(sx, az));
        let y = _mm512_sub_ps(_mm512_sub_ps(_mm512_set1_ps(b.p[v][ky][j]), oy), _mm512_mul_ps(sy, az));
        (x, y, az)
    };
    let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (project(0), project(1), project(2));
    let u = _mm512_sub_ps(_mm512_mul_ps(cx, by), _mm512_mul_ps(cy, bx));
    let v = _mm512_sub_ps(_mm512_mul_ps(ax, cy), _mm512_mul_ps(ay, cx));
    let w = _mm512_sub_ps(_mm512_mul_ps(bx, ay), _mm512_mul_ps(by, ax));
    let zero = _mm512_setzero_ps();
    // Mixed signs: the sign bits differ (read as integers below zero).
    let bits = _mm512_castps_si512;
    let mixed = _mm512_cmplt_epi32_mask(_mm512_or_si512(_mm512_xor_si512(bits(u), bits(v)), _mm512_xor_si512(bits(u), bits(w))), _mm512_setzero_si512());
    // Most rays reaching a leaf miss most of its triangles, and the edge functions say
    // so: all three non-zero and not NaN (their product's magnitude above zero, as in
    // `triangles_sse`) with mixed signs.
    let nonzero = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(_mm512_abs_ps(_mm512_mul_ps(_mm512_mul_ps(u, v), w)), zero);
    if active & !(nonzero & mixed) == 0 {
        return (0, 0, zero, zero, zero);
    }
    let eq0 = |x: __m512| _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(x, zero);
    let undecided_edges = eq0(u) | eq0(v) | eq0(w) | _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(u, v) | _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(w, w);
    // Where the edge functions are decided, mixed signs are "outside".
    let outside = mixed;
    let det = _mm512_add_ps(_mm512_add_ps(u, v), w);
    let (az, bz, cz) = (_mm512_mul_ps(sz, az), _mm512_mul_ps(sz, bz), _mm512_mul_ps(sz, cz));
    let t_scaled = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(u, az), _mm512_mul_ps(v, bz)), _mm512_mul_ps(w, cz));
    let inv_det = _mm512_div_ps(_mm512_set1_ps(1.0), det);
    let t = _mm512_mul_ps(t_scaled, inv_det);
    let abs = _mm512_abs_ps;
    let max3 = |a: __m512, b: __m512, c: __m512| _mm512_max_ps(_mm512_max_ps(abs(a), abs(b)), abs(c));
    let (max_zt, max_xt, max_yt, max_e) = (max3(az, bz, cz), max3(ax, bx, cx), max3(ay, by, cy), max3(u, v, w));
    let g = |n: u32| _mm512_set1_ps(gamma(n));
    let delta_z = _mm512_mul_ps(g(3), max_zt);
    let delta_x = _mm512_mul_ps(g(5), _mm512_add_ps(max_xt, max_zt));
    let delta_y = _mm512_mul_ps(g(5), _mm512_add_ps(max_yt, max_zt));
    let delta_e = _mm512_mul_ps(_mm512_set1_ps(2.0), _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(_mm512_mul_ps(g(2), max_xt), max_yt), _mm512_mul_ps(delta_y, max_xt)), _mm512_mul_ps(delta_x, max_yt)));
    let delta_t = _mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(3.0), _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(_mm512_mul_ps(g(3), max_e), max_zt), _mm512_mul_ps(delta_e, max_zt)), _mm512_mul_ps(delta_z, max_e))), abs(inv_det));
    let inf = _mm512_set1_ps(f32::INFINITY);
    let finite = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(abs(t), inf) & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(abs(delta_t), inf);
    let ahead = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(t, delta_t);
    let behind = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(t, _mm512_sub_ps(zero, delta_t));
    let rejected = !undecided_edges & (outside | eq0(det));
    let decided_t = finite & (ahead | behind);
    let in_range = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(t, p.t_min) & _mm512_cmp_ps_mask::<_CMP_LE_OQ>(t, t_max);
    let hit = active & !(undecided_edges | rejected) & finite & ahead & in_range;
    let exact = active & (undecided_edges | !(rejected | decided_t));
    (hit, exact, t, _mm512_mul_ps(v, inv_det), _mm512_mul_ps(w, inv_det))
}

#[cfg(test)]
pub(super) mod tests {
    use raylab_core::{Pcg32, Ray, Vec3};

    use super::super::{node::WideNode, quant::QuantNode, WideBvh};
    use super::PACKET;
    use crate::{binary_for_wide, BuildOptions, Counters, PrimHit, Primitives};

    /// Triangles (through the packed blocks) then spheres (lanes that are not triangles).
    pub(in crate::wide) struct Mixed {
        pub(in crate::wide) tris: Vec<[Vec3; 3]>,
        spheres: Vec<(Vec3, f32)>,
    }

    impl Mixed {
        /// One triangle at `z = 2`, facing rays from the origin along `+z`.
        pub(in crate::wide) fn one_triangle() -> Mixed {
            Mixed { tris: vec![[Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0)]], spheres: vec![] }
        }
    }

    impl Primitives for Mixed {
        fn len(&self) -> usize {
            self.tris.len() + self.spheres.len()
        }
        fn bounds(&self, i: u32) -> raylab_core::Aabb {
            match self.triangle(i) {
                Some(t) => raylab_core::Aabb::from_points(t),
                None => {
                    let (c, r) = self.spheres[i as usize - self.tris.len()];
                    raylab_core::Aabb::new(c - r, c + r)
                }
            }
        }
        fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
            match self.triangle(i) {
                Some([a, b, c]) => raylab_core::intersect::triangle(ray, a, b, c).map(|(t, u, v)| PrimHit { t, u, v }),
                None => {
                    let (c, r) = self.spheres[i as usize - self.tris.len()];
                    raylab_core::intersect::sphere(ray, c, r).map(|t| PrimHit { t, u: 0.0, v: 0.0 })
                }
            }
        }
        fn triangle(&self, i: u32) -> Option<[Vec3; 3]> {
            self.tris.get(i as usize).copied()
        }
    }

    /// Random small triangles, a grid of quads whose shared edges and vertices rays pass
    /// through, a triangle repeated under three indices (exact ties: the lowest index
    /// wins), zero-area triangles (the scalar kernel's cases), and spheres.
    pub(in crate::wide) fn scene(rng: &mut Pcg32) -> Mixed {
        let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
        let mut tris: Vec<[Vec3; 3]> = (0..600).map(|_| {
            let c = r();
            [c, c + 0.2 * r(), c + 0.2 * r()]
        }).collect();
        for i in 0..8 {
            for j in 0..8 {
                let p = |a: i32, b: i32| Vec3::new((i + a) as f32 * 0.25 - 1.0, (j + b) as f32 * 0.25 - 1.0, 0.5);
                tris.push([p(0, 0), p(1, 0), p(1, 1)]);
                tris.push([p(0, 0), p(1, 1), p(0, 1)]);
            }
        }
        let dup = [Vec3::new(-0.5, -0.5, -0.9), Vec3::new(0.5, -0.5, -0.9), Vec3::new(0.0, 0.5, -0.9)];
        tris.extend([dup; 3]);
        let p = r();
        tris.extend([[p, p, p], [p, p + Vec3::X * 0.1, p + Vec3::X * 0.2]]);
        let spheres = (0..40).map(|k| (r(), 0.05 + 0.0025 * k as f32)).collect();
        Mixed { tris, spheres }
    }

    /// Packets of 1 to 16 rays from one origin in a narrow cone (a camera tile), some with
    /// a `t_min` above zero or a short `t_max`, and some through grid vertices exactly.
    pub(in crate::wide) fn packets(rng: &mut Pcg32, prims: &Mixed) -> Vec<Vec<Ray>> {
        (0..400).map(|k| {
            // Every eleventh packet leaves a point of a tilted triangle (hits at t within
            // the error bound of zero, some decided by the scalar kernel).
            let origin = if k % 11 == 0 {
                let [a, b, c] = prims.tris[k];
                a + 0.3 * (b - a) + 0.3 * (c - a)
            } else {
                Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 6.0 - 3.0
            };
            let aim = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
            let n = if k % 5 == 0 { 1 + k % PACKET } else { PACKET };
            (0..n).map(|r| {
                let target = if k % 11 == 0 { origin + Vec3::new((r % 4) as f32 - 1.5, (r / 4) as f32 - 1.5, if k % 2 == 0 { 2.0 } else { -2.0 }) } else if k % 7 == 0 { Vec3::new((r % 4) as f32 * 0.25 - 0.5, (r / 4) as f32 * 0.25 - 0.5, 0.5) } else { aim + Vec3::new((r % 4) as f32, (r / 4) as f32, 0.0) * 0.02 };
                let mut ray = Ray::new(origin, target - origin);
                if k % 3 == 0 {
                    ray.t_min = 0.3;
                }
                if k % 4 == 1 {
                    ray.t_max = 0.5 + r as f32 * 0.05;
                }
                ray
            }).collect()
        }).collect()
    }

    /// Every packet against its rays alone; at least `min_taken` packets through the
    /// ray-major path and `min_hits` hits.
    fn check<N: super::super::node::Layout<8>>(bvh: &WideBvh<8, N>, prims: &Mixed, packets: &[Vec<Ray>], min_taken: usize, min_hits: usize) {
        let (mut taken, mut hits) = (0, 0);
        for (k, rays) in packets.iter().enumerate() {
            let mut out = vec![None; rays.len()];
            let mut counted = vec![None; rays.len()];
            let mut c = Counters::default();
            // SAFETY: the caller checked AVX-512F and VL, AVX2, BMI1 and BMI2.
            let took = unsafe { super::closest::<_, 8, N, false>(bvh, prims, rays, &mut out, &mut Counters::default()) };
            // SAFETY: as above.
            assert_eq!(unsafe { super::closest::<_, 8, N, true>(bvh, prims, rays, &mut counted, &mut c) }, took);
            if !took {
                assert!(out.iter().all(Option::is_none), "packet {k}: declined, yet answers written");
                continue;
            }
            taken += 1;
            for (r, ray) in rays.iter().enumerate() {
                let want = super::super::traverse::closest::<_, 8, N, true, false>(bvh, prims, ray, &mut Counters::default());
                assert_eq!(out[r], want, "packet {k} ray {r}");
                assert_eq!(counted[r], want, "packet {k} ray {r}: counting build");
                hits += usize::from(want.is_some());
            }
            assert_eq!(c.rays, rays.len() as u64, "packet {k}");
            // Sixteen copies of a ray walk as the ray does alone: sixteen times its work.
            let copies = [rays[0]; PACKET];
            let (mut c16, mut c1) = (Counters::default(), Counters::default());
            // SAFETY: as above.
            assert!(unsafe { super::closest::<_, 8, N, true>(bvh, prims, &copies, &mut [None; PACKET], &mut c16) });
            super::super::traverse::closest::<_, 8, N, true, true>(bvh, prims, &rays[0], &mut c1);
            assert_eq!((c16.nodes_visited, c16.prim_tests), (16 * c1.nodes_visited, 16 * c1.prim_tests), "packet {k}: copies");
        }
        assert!(taken >= min_taken && hits >= min_hits, "too few packets through the ray-major path: {taken} packets, {hits} hits");
    }

    #[test]
    fn coherent_packets_get_their_single_ray_answers() {
        use std::is_x86_feature_detected as has;
        if !(has!("avx512f") && has!("avx512vl") && has!("avx2") && has!("bmi1") && has!("bmi2")) {
            eprintln!("no AVX-512 on this CPU: the ray-major path is not run");
            return;
        }
        let mut rng = Pcg32::new(11, 3);
        let prims = scene(&mut rng);
        let packets = packets(&mut rng, &prims);
        let binary = binary_for_wide(&prims, &BuildOptions::default(), "bvh");
        check(&WideBvh::<8, WideNode<8>>::from_binary(&binary, &prims, "bvh8"), &prims, &packets, 300, 2000);
        check(&WideBvh::<8, QuantNode>::from_binary(&binary, &prims, "bvh8q"), &prims, &packets, 300, 2000);
    }

    /// The ray-major triangle kernel decides each ray as `triangles_sse` decides that ray
    /// alone: the same hits with the same bits of `t` and barycentrics, and the same rays
    /// left to the scalar kernel. Random, degenerate, tiny and huge triangles, origins on
    /// the triangles (t within the error bound of zero) and limited `t` ranges.
    #[test]
    fn the_triangle_kernel_matches_the_four_wide_kernel_ray_by_ray() {
        use super::super::kernels::triangles_sse;
        use raylab_core::intersect::ShearedRay;
        use std::arch::x86_64::*;
        use std::is_x86_feature_detected as has;
        if !(has!("avx512f") && has!("avx512vl") && has!("avx2")) {
            return;
        }
        let mut rng = Pcg32::new(13, 5);
        let mut r = |scale: f32| Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5) * scale;
        let (mut hits, mut exact, mut packets) = (0, 0, 0);
        for k in 0..6000 {
            let scale = [1.0, 1e-30, 1e30, 3e38, 1e6][k % 5];
            let b = super::super::kernels::tests::random_block(k, 4, scale, &mut r);
            let origin = match k % 3 {
                0 => r(2.0 * scale),
                1 => Vec3::ZERO,
                _ => b.vertex(2, 0) + 0.3 * (b.vertex(2, 1) - b.vertex(2, 0)) + 0.3 * (b.vertex(2, 2) - b.vertex(2, 0)),
            };
            let aim = (b.vertex(k % 4, 0) + b.vertex(k % 4, 1) + b.vertex(k % 4, 2)) / 3.0 - origin;
            let rays: Vec<Ray> = (0..PACKET).map(|q| {
                let d = aim + Vec3::new((q % 4) as f32 - 1.5, (q / 4) as f32 - 1.5, 0.0) * 0.01 * aim.length();
                let mut ray = Ray::new(origin, if k % 11 == 0 { -d } else { d });
                if k % 4 == 0 {
                    ray.t_max = 0.9 + 0.01 * q as f32;
                }
                ray
            }).collect();
            // SAFETY: features checked above.
            let Some((p, t_max)) = (unsafe { super::Packet::new(&rays) }) else { continue };
            packets += 1;
            let mut t_maxes = [0.0f32; PACKET];
            // SAFETY: as above; the array holds 16 f32.
            unsafe { _mm512_storeu_ps(t_maxes.as_mut_ptr(), t_max) };
            for j in 0..4 {
                // SAFETY: as above.
                let (hit, ex, t, u, v) = unsafe { super::triangle(&b, j, &p, p.axes, 0xFFFF, t_max) };
                let lanes = |x: __m512| {
                    let mut a = [0.0f32; PACKET];
                    // SAFETY: as above.
                    unsafe { _mm512_storeu_ps(a.as_mut_ptr(), x) };
                    a
                };
                let (t, u, v) = (lanes(t), lanes(u), lanes(v));
                for (q, ray) in rays.iter().enumerate() {
                    let one = triangles_sse(&b, &ShearedRay::new(ray), ray.t_min, t_maxes[q]);
                    let bit = 1 << j;
                    assert_eq!((hit >> q & 1 != 0, ex >> q & 1 != 0), (one.hit & bit != 0, one.exact & bit != 0), "block {k} triangle {j} ray {q}");
                    if one.hit & bit != 0 {
                        assert_eq!([t[q], u[q], v[q]].map(f32::to_bits), [one.t[j], one.u[j], one.v[j]].map(f32::to_bits), "block {k} triangle {j} ray {q}");
                        hits += 1;
                    }
                    exact += usize::from(one.exact & bit != 0);
                }
            }
        }
        assert!(packets > 3000 && hits > 10000 && exact > 1000, "too few cases: {packets} packets, {hits} hits, {exact} left to the scalar kernel");
    }

    /// The frustum test keeps every child that any ray of the packet enters, with an entry
    /// distance no greater than that ray's: random boxes (empty, flat, huge and tiny ones
    /// among them) against packets spread over a wide cone, some from scattered origins.
    #[test]
    fn the_frustum_keeps_every_child_a_ray_enters() {
        use super::super::kernels::{slabs_avx2, RayBoxes};
        use std::arch::x86_64::*;
        use std::is_x86_feature_detected as has;
        if !(has!("avx512f") && has!("avx512vl") && has!("avx2")) {
            return;
        }
        let mut rng = Pcg32::new(17, 9);
        let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
        let (mut entered, mut culled, mut packets) = (0, 0, 0);
        for k in 0..3000 {
            let scale = [1.0, 1e-3, 1e4][k % 3];
            let mut node = WideNode::<8>::EMPTY_NODE;
            for l in 0..8 - k % 3 {
                let (c, e) = (r() * 2.0 * scale, (r().abs() + Vec3::splat(if l == 3 { 0.0 } else { 0.01 })) * scale);
                let e = if l == 2 { Vec3::new(e.x, 0.0, e.z) } else { e };
                node.set(l, &raylab_core::Aabb::new(c - e, c + e), l as u32);
            }
            let origin = r() * 5.0 * scale;
            let target = node.child_bounds(k % 5);
            let aim = (target.min + target.max) * 0.5 - origin;
            let spread = [0.01, 0.2, 1.0][k % 3] * aim.length();
            let rays: Vec<Ray> = (0..PACKET).map(|q| {
                let o = if k % 4 == 0 { origin + r() * 0.5 * scale } else { origin };
                let mut ray = Ray::new(o, aim + Vec3::new((q % 4) as f32 - 1.5, (q / 4) as f32 - 1.5, 0.0) * spread * 0.1);
                ray.t_min = if k % 5 == 0 { 0.1 * q as f32 } else { 0.0 };
                ray.t_max = if k % 6 == 0 { 1.0 + q as f32 } else { f32::INFINITY };
                ray
            }).collect();
            // SAFETY: features checked above.
            let Some((p, t_max)) = (unsafe { super::Packet::new(&rays) }) else { continue };
            let f = p.frustum.as_ref().expect("finite constants give a frustum");
            packets += 1;
            // SAFETY: as above.
            let far = unsafe { _mm512_mul_ps(t_max, _mm512_set1_ps(super::ROBUST_FAR)) };
            let mut far_each = [0.0f32; PACKET];
            // SAFETY: as above; the array holds 16 f32.
            unsafe { _mm512_storeu_ps(far_each.as_mut_ptr(), far) };
            // SAFETY: as above.
            let (kept, t0) = unsafe { super::frustum_slabs(&node, f, p.near_rows, p.far_rows, _mm512_reduce_max_ps(far)) };
            let mut bound = [0.0f32; 8];
            // SAFETY: as above; the array holds 8 f32.
            unsafe { _mm256_storeu_ps(bound.as_mut_ptr(), t0) };
            let mut any = 0u32;
            for (q, &far_q) in far_each.iter().enumerate() {
                // SAFETY: as above.
                let (n, x) = unsafe { slabs_avx2(&node, &RayBoxes::new(&rays[q]), far_q) };
                let (mut near, mut exit) = ([0.0f32; 8], [0.0f32; 8]);
                // SAFETY: as above.
                unsafe { (_mm256_storeu_ps(near.as_mut_ptr(), n), _mm256_storeu_ps(exit.as_mut_ptr(), x)) };
                for l in 0..8 {
                    if near[l] <= exit[l] {
                        any |= 1 << l;
                        assert!(kept & 1 << l != 0, "packet {k}: ray {q} enters child {l}, culled by the frustum");
                        assert!(bound[l] <= near[l], "packet {k}: child {l}: frustum entry {} above ray {q}'s {}", bound[l], near[l]);
                    }
                }
            }
            entered += any.count_ones();
            culled += (!kept & 0xFF).count_ones();
        }
        assert!(packets > 2000 && entered > 3000 && culled > 3000, "too few cases: {packets} packets, {entered} children entered, {culled} culled");
    }

    /// The packet's constants, loaded by the transpose and reduced all at once, are each
    /// ray's own (`RayBoxes::new`, `ShearedRay::new`) and their exact extremes, for packets
    /// of 1 to 16 rays (lanes past the count repeat the last ray).
    #[test]
    fn packet_constants_are_each_rays_own_and_their_extremes() {
        use super::super::kernels::RayBoxes;
        use raylab_core::intersect::ShearedRay;
        use std::is_x86_feature_detected as has;
        if !(has!("avx512f") && has!("avx512vl") && has!("avx2")) {
            return;
        }
        let mut rng = Pcg32::new(3, 9);
        let mut f = |s: f32| (rng.next_f32() - 0.5) * s;
        let lanes = |x: core::arch::x86_64::__m512| -> [f32; PACKET] { unsafe { std::mem::transmute(x) } };
        let mut taken = 0;
        for k in 0..400 {
            let n = 1 + k % PACKET;
            let rays: Vec<Ray> = (0..n).map(|_| Ray::segment(Vec3::new(f(8.0), f(8.0), f(8.0)), Vec3::new(0.3 + f(0.2), -0.2 + f(0.2), 1.0 + f(0.4)), f(0.1).abs(), 5.0 + f(4.0))).collect();
            // SAFETY: features checked above.
            let Some((p, t_max)) = (unsafe { super::Packet::new(&rays) }) else { continue };
            taken += 1;
            let fr = p.frustum.as_ref().expect("finite constants");
            for r in 0..PACKET {
                let ray = &rays[r.min(n - 1)];
                let (rb, sh) = (RayBoxes::new(ray), ShearedRay::new(ray));
                let bits = |x: &[f32]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                let got = |xs: &[core::arch::x86_64::__m512]| xs.iter().map(|&x| lanes(x)[r]).collect::<Vec<_>>();
                assert_eq!(bits(&got(&p.origin)), bits(&rb.origin), "packet {k} ray {r}: origin");
                assert_eq!(bits(&got(&p.inv)), bits(&rb.inv), "packet {k} ray {r}: inverse");
                assert_eq!(bits(&got(&p.inv_far)), bits(&rb.inv_far), "packet {k} ray {r}: inverse for far planes");
                assert_eq!(bits(&got(&p.shear)), bits(&[sh.sx, sh.sy, sh.sz]), "packet {k} ray {r}: shear");
                assert_eq!((lanes(p.t_min)[r], lanes(t_max)[r]), (rb.t_min, ray.t_max), "packet {k} ray {r}: interval");
                assert_eq!(p.axes, (sh.kx, sh.ky, sh.kz), "packet {k}: shear axes");
                assert_eq!((p.near_rows, p.far_rows), (rb.near, rb.far), "packet {k}: box rows");
            }
            let ext = |g: &dyn Fn(&Ray) -> f32| (rays.iter().map(g).fold(f32::INFINITY, f32::min), rays.iter().map(g).fold(f32::NEG_INFINITY, f32::max));
            for a in 0..3 {
                let (lo, hi) = ext(&|r: &Ray| r.origin[a]);
                let (near, far) = if p.near_rows[a] == a { (hi, lo) } else { (lo, hi) };
                assert_eq!((fr.near_origin[a], fr.far_origin[a]), (near, far), "packet {k} axis {a}: frustum origins");
                let (lo, hi) = ext(&|r: &Ray| RayBoxes::new(r).inv[a]);
                assert_eq!(fr.inv[a], [lo, hi], "packet {k} axis {a}: frustum inverses");
            }
            assert_eq!(fr.t_min, ext(&|r: &Ray| r.t_min + 0.0).0, "packet {k}: frustum t_min");
        }
        assert!(taken > 300, "too few packets taken: {taken}");
    }

    /// A ray with a zero direction component has an infinite inverse: no frustum, and the
    /// packet still gets its single-ray answers.
    #[test]
    fn packets_with_an_infinite_inverse_have_no_frustum() {
        use std::is_x86_feature_detected as has;
        if !(has!("avx512f") && has!("avx512vl") && has!("avx2") && has!("bmi1") && has!("bmi2")) {
            return;
        }
        let rays: Vec<Ray> = (0..PACKET).map(|q| Ray::new(Vec3::new(0.01 * q as f32, 0.0, 0.0), Vec3::new(0.0, 0.1, 1.0))).collect();
        // SAFETY: features checked above.
        assert!(unsafe { super::Packet::new(&rays) }.is_some_and(|(p, _)| p.frustum.is_none()));
        let mut rng = Pcg32::new(5, 7);
        let prims = scene(&mut rng);
        let bvh = WideBvh::<8, WideNode<8>>::from_binary(&binary_for_wide(&prims, &BuildOptions::default(), "bvh"), &prims, "bvh8");
        let packets: Vec<Vec<Ray>> = (0..50).map(|k| (0..PACKET).map(|q| Ray::new(Vec3::new(-0.9 + 0.036 * k as f32, -0.9 + 0.1 * q as f32, -3.0), Vec3::new(0.0, 0.05, 1.0))).collect()).collect();
        check(&bvh, &prims, &packets[..], 40, 100);
    }

    #[test]
    fn packets_of_mixed_octants_or_axes_are_declined() {
        use std::is_x86_feature_detected as has;
        if !(has!("avx512f") && has!("avx512vl") && has!("avx2") && has!("bmi1") && has!("bmi2")) {
            return;
        }
        let prims = Mixed::one_triangle();
        let bvh = WideBvh::<8, WideNode<8>>::from_binary(&binary_for_wide(&prims, &BuildOptions::default(), "bvh"), &prims, "bvh8");
        let run = |dirs: &[Vec3]| {
            let rays: Vec<Ray> = dirs.iter().map(|&d| Ray::new(Vec3::ZERO, d)).collect();
            let mut out = vec![None; rays.len()];
            // SAFETY: features checked above.
            let took = unsafe { super::closest::<_, 8, WideNode<8>, false>(&bvh, &prims, &rays, &mut out, &mut Counters::default()) };
            (took, out)
        };
        // Along +z, all: taken, both hit at t = 2 (direction z = 1).
        let (took, out) = run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(0.2, 0.1, 1.0)]);
        assert!(took);
        assert_eq!(out.iter().map(|h| h.map(|h| (h.prim, h.t))).collect::<Vec<_>>(), [Some((0, 2.0)); 2]);
        // One ray with a negative x: other box rows.
        assert!(!run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(-0.1, 0.1, 1.0)]).0);
        // One ray mostly along x: other shear axes.
        assert!(!run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(2.0, 0.1, 1.0)]).0);
        // Along -z for one: other signs and a swapped shear.
        assert!(!run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(0.1, 0.1, -1.0)]).0);
    }
}
