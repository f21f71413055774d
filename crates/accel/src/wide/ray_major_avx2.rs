//! Closest hits of an 8-ray packet with AVX2, ray-major as Embree's `rtcIntersect8`: ray
//! `r` lives in lane `r` of every 256-bit register. CPUs without AVX-512 trace a 16-ray
//! camera tile as two such packets of 4×2 rays, as Embree runs `rtcIntersect16` there.
//!
//! The same walk as the AVX-512 one (`ray_major.rs`, whose documentation gives the
//! reasoning): each lane does the single-ray kernels' IEEE operations in the same order,
//! hits are kept as the least `(t, prim)`, a node is first tested against the packet's
//! frustum and only the children it keeps are tested ray by ray in the eight lanes, and
//! stack entries carry each ray's entry distance. Masks are bits of a `u32` (from
//! `movemask`), turned back into lane masks where a blend needs one.

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use raylab_core::intersect::ShearedRay;
use raylab_core::{gamma, Ray};

use super::kernels::{BlockRay, ROBUST_FAR};
use super::node::{is_leaf, Layout, TriBlock, WideNode, EMPTY};
use super::packet::prefetch;
use super::ray_major::{frustum_slabs, Frustum, FEW_IN_LEAF};
use super::traverse::{block_closest, exact_lane, insert_sorted, leaf_slice, occupied, wins, STACK};
use super::WideBvh;
use crate::{Counters, Hit, Primitives};

/// Rays per packet.
pub const RAYS: usize = 8;
const ALL: u32 = (1 << RAYS) - 1;

/// Eight lanes, aligned for 256-bit loads and stores.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct Lanes([f32; RAYS]);

/// The packet's per-ray constants, one lane per ray, and what its rays share.
struct Packet {
    origin: [__m256; 3],
    inv: [__m256; 3],
    inv_far: [__m256; 3],
    t_min: __m256,
    /// Shear `d[kx]/d[kz]`, `d[ky]/d[kz]` and scale `1/d[kz]`.
    shear: [__m256; 3],
    near_rows: [usize; 3],
    far_rows: [usize; 3],
    /// `(kx, ky, kz)` of every ray's `ShearedRay`.
    axes: (usize, usize, usize),
    /// `origin` and `shear` stored lane by lane (6 rows).
    each: [Lanes; 6],
    frustum: Option<Frustum>,
}

/// The lanes of `v`.
#[inline]
#[target_feature(enable = "avx2")]
fn lanes(v: __m256) -> [f32; RAYS] {
    let mut a = Lanes([0.0; RAYS]);
    // SAFETY: `Lanes` is 32-byte aligned.
    unsafe { _mm256_store_ps(a.0.as_mut_ptr(), v) };
    a.0
}

/// The lane mask (all bits set) of the lanes whose bit is set in `bits`.
#[inline]
#[target_feature(enable = "avx2")]
fn lane_mask(bits: u32) -> __m256 {
    let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(bits as i32), lane_bits), lane_bits))
}

/// The bits of the lanes where `x` holds.
#[inline]
#[target_feature(enable = "avx2")]
fn bits(x: __m256) -> u32 {
    _mm256_movemask_ps(x) as u32
}

impl Packet {
    /// Ray `r`'s `ShearedRay`.
    fn sheared(&self, r: usize) -> ShearedRay {
        let e = |k: usize| self.each[k].0[r];
        let (kx, ky, kz) = self.axes;
        ShearedRay { origin: raylab_core::Vec3::new(e(0), e(1), e(2)), kx, ky, kz, sx: e(3), sy: e(4), sz: e(5) }
    }

    /// The constants of `rays` (1 to [`RAYS`]; lanes past their count repeat the last
    /// ray), computed as `RayBoxes::new` and `ShearedRay::new` do ray by ray, and their
    /// `t_max`; `None` unless they share box rows and shear axes.
    #[target_feature(enable = "avx2")]
    fn new(rays: &[Ray]) -> Option<(Packet, __m256)> {
        let n = rays.len();
        let padded: [Ray; RAYS];
        let src = if n == RAYS {
            rays.as_ptr()
        } else {
            padded = std::array::from_fn(|r| rays[r.min(n - 1)]);
            padded.as_ptr()
        };
        // SAFETY: `src` points to 8 rays of 8 f32 each, one per 32-byte load.
        let fields = transpose(std::array::from_fn(|r| unsafe { _mm256_loadu_ps(src.cast::<f32>().add(RAY_F32 * r)) }));
        let field = |offset: usize| fields[offset / 4];
        let (o, d) = (std::mem::offset_of!(Ray, origin), std::mem::offset_of!(Ray, dir));
        let (origin, dir) = ([0, 4, 8].map(|a| field(o + a)), [0, 4, 8].map(|a| field(d + a)));
        let (t_min, t_max) = (field(std::mem::offset_of!(Ray, t_min)), field(std::mem::offset_of!(Ray, t_max)));
        let zero = _mm256_setzero_ps();
        let one = _mm256_set1_ps(1.0);
        let inv = dir.map(|d| _mm256_div_ps(one, _mm256_add_ps(d, zero)));
        let negative = inv.map(|i| bits(_mm256_cmp_ps::<_CMP_LT_OQ>(i, zero)));
        if negative.iter().any(|&m| m != 0 && m != ALL) {
            return None;
        }
        let near_rows = [0, 1, 2].map(|a| if negative[a] != 0 { 3 + a } else { a });
        let far_rows = [0, 1, 2].map(|a| if negative[a] != 0 { a } else { 3 + a });
        let sign = _mm256_set1_ps(-0.0);
        let ad = dir.map(|d| _mm256_andnot_ps(sign, d));
        let gt = |a: usize, b: usize| bits(_mm256_cmp_ps::<_CMP_GT_OQ>(ad[a], ad[b]));
        let (x0, z0, yz) = (gt(0, 1), gt(0, 2), gt(1, 2));
        let (along_x, along_y) = (x0 & z0, !x0 & yz & ALL);
        let kz = match (along_x, along_y) {
            (ALL, _) => 0,
            (_, ALL) => 1,
            (0, 0) => 2,
            _ => return None,
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        match bits(_mm256_cmp_ps::<_CMP_LT_OQ>(dir[kz], zero)) {
            0 => {}
            ALL => std::mem::swap(&mut kx, &mut ky),
            _ => return None,
        }
        // `1/d[kz]` is `inv[kz]` unless `d[kz]` is `-0` (see `ray_major.rs`).
        if bits(_mm256_cmp_ps::<_CMP_EQ_OQ>(dir[kz], zero)) != 0 {
            return None;
        }
        let shear = [_mm256_div_ps(dir[kx], dir[kz]), _mm256_div_ps(dir[ky], dir[kz]), inv[kz]];
        let inv_far = inv.map(|i| _mm256_mul_ps(i, _mm256_set1_ps(ROBUST_FAR)));
        let mut each = [Lanes([0.0; RAYS]); 6];
        for (k, x) in origin.iter().chain(&shear).enumerate() {
            each[k].0 = lanes(*x);
        }
        let inf = _mm256_set1_ps(f32::INFINITY);
        let finite = |x: &__m256| bits(_mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(sign, *x), inf)) == ALL;
        let frustum = (origin.iter().chain(&inv).chain(&inv_far).all(finite) && finite(&t_min)).then(|| {
            let along = |a: usize, pos: f32, neg: f32| if negative[a] == 0 { pos } else { neg };
            let inv = inv.map(|i| [least_of(i), most_of(i)]);
            Frustum {
                near_origin: [0, 1, 2].map(|a| along(a, most_of(origin[a]), least_of(origin[a]))),
                far_origin: [0, 1, 2].map(|a| along(a, least_of(origin[a]), most_of(origin[a]))),
                inv,
                // Rounding is monotone: the extremes of `inv · ROBUST_FAR` are those of `inv`
                // times it, as each lane computes it.
                inv_far: inv.map(|[l, h]| [l * ROBUST_FAR, h * ROBUST_FAR]),
                t_min: least_of(t_min),
            }
        });
        Some((Packet { origin, inv, inv_far, t_min, shear, near_rows, far_rows, axes: (kx, ky, kz), each, frustum }, t_max))
    }
}

/// Floats per [`Ray`]: a ray loads as one 32-byte register.
const RAY_F32: usize = 8;
const _: () = assert!(std::mem::size_of::<Ray>() == 4 * RAY_F32);

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

/// The greatest lane of `v`.
#[inline]
#[target_feature(enable = "avx2")]
fn most_of(v: __m256) -> f32 {
    let m = _mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
    let m = _mm_max_ps(m, _mm_movehl_ps(m, m));
    _mm_cvtss_f32(_mm_max_ss(m, _mm_movehdup_ps(m)))
}

/// The least lane of `v`.
#[inline]
#[target_feature(enable = "avx2")]
fn least_of(v: __m256) -> f32 {
    let m = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
    let m = _mm_min_ps(m, _mm_movehl_ps(m, m));
    _mm_cvtss_f32(_mm_min_ss(m, _mm_movehdup_ps(m)))
}

/// What each ray has found so far: its `t_max` (the best hit's distance once it has one),
/// the best primitive (`u32::MAX` for none) and its barycentrics.
struct Best {
    t: __m256,
    prim: __m256i,
    u: __m256,
    v: __m256,
}

/// [`Best`] stored lane by lane.
struct BestLanes {
    t: Lanes,
    u: Lanes,
    v: Lanes,
    prim: [u32; RAYS],
}

impl Best {
    #[target_feature(enable = "avx2")]
    fn store(&self) -> BestLanes {
        let mut l = BestLanes { t: Lanes([0.0; RAYS]), u: Lanes([0.0; RAYS]), v: Lanes([0.0; RAYS]), prim: [0; RAYS] };
        // SAFETY: `Lanes` is 32-byte aligned, and every array holds 8 lanes of 4 bytes.
        unsafe {
            _mm256_store_ps(l.t.0.as_mut_ptr(), self.t);
            _mm256_store_ps(l.u.0.as_mut_ptr(), self.u);
            _mm256_store_ps(l.v.0.as_mut_ptr(), self.v);
            _mm256_storeu_si256(l.prim.as_mut_ptr().cast(), self.prim);
        }
        l
    }

    #[target_feature(enable = "avx2")]
    fn load(l: &BestLanes) -> Best {
        // SAFETY: as in `store`.
        unsafe { Best { t: _mm256_load_ps(l.t.0.as_ptr()), u: _mm256_load_ps(l.u.0.as_ptr()), v: _mm256_load_ps(l.v.0.as_ptr()), prim: _mm256_loadu_si256(l.prim.as_ptr().cast()) } }
    }

    /// Ray `r`'s hit so far.
    fn hit(l: &BestLanes, r: usize) -> Option<Hit> {
        (l.prim[r] != u32::MAX).then(|| Hit { t: l.t.0[r], prim: l.prim[r], u: l.u.0[r], v: l.v.0[r] })
    }
}

/// Closest hits of `rays` (1 to [`RAYS`]) into `out` (as long as `rays`); `false`, with
/// `out` and `c` untouched, for a packet whose rays do not share their box rows and shear
/// axes. Counting (`COUNT`) charges as the other packet paths do: each node once per
/// active ray, each block's occupied lanes once per ray tested against it.
///
/// # Safety
/// The CPU must support AVX2.
#[target_feature(enable = "avx2")]
pub(super) unsafe fn closest<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool>(bvh: &WideBvh<W, N>, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) -> bool {
    let n = rays.len();
    debug_assert!(W == 8 && (1..=RAYS).contains(&n) && out.len() == n);
    let Some((p, t_max)) = Packet::new(rays) else { return false };
    out.fill(None);
    if COUNT {
        c.rays += n as u64;
    }
    if bvh.root == EMPTY {
        return true;
    }
    let (near_rows, far_rows, (kx, ky, kz)) = (p.near_rows, p.far_rows, p.axes);
    let zero = _mm256_setzero_ps();
    let inf = _mm256_set1_ps(f32::INFINITY);
    let mut best = Best { t: t_max, prim: _mm256_set1_epi32(-1), u: zero, v: zero };
    let mut far = _mm256_mul_ps(best.t, _mm256_set1_ps(ROBUST_FAR));
    let mut far_max = most_of(far);
    let mut stack_node = [const { MaybeUninit::<u32>::uninit() }; STACK];
    let mut stack_t = [const { MaybeUninit::<Lanes>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = bvh.root;
    let all = if n == RAYS { ALL } else { (1 << n) - 1 };
    let mut cur_t = _mm256_blendv_ps(inf, p.t_min, lane_mask(all));
    'walk: loop {
        // Rays still in this subtree: entered it, and their hit so far is not nearer.
        let active = bits(_mm256_cmp_ps::<_CMP_LE_OQ>(cur_t, far)) & all;
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
                far = _mm256_mul_ps(best.t, _mm256_set1_ps(ROBUST_FAR));
                far_max = most_of(far);
            } else {
                // Children any ray entered, the nearest first; the others wait on the
                // stack with each ray's entry distance.
                let lane_bits = W as u32 - 1;
                let mut entry = [const { MaybeUninit::<Lanes>::uninit() }; 8];
                let mut keys = [0u32; 8];
                let mut k = 0;
                bvh.nodes[cur as usize].with_decoded(|node| {
                    // SAFETY: `W == 8` (the caller's check), so the types are the same.
                    let node8 = unsafe { &*(node as *const WideNode<W>).cast::<WideNode<8>>() };
                    let mut order = [0.0f32; 8];
                    let mut candidates = match &p.frustum {
                        Some(f) => {
                            let (m, t0) = frustum_slabs(node8, f, near_rows, far_rows, far_max);
                            order = lanes(t0);
                            m
                        }
                        None => 0xFF,
                    };
                    while candidates != 0 {
                        let l = candidates.trailing_zeros() as usize;
                        candidates &= candidates - 1;
                        if node8.child[l] == EMPTY {
                            continue;
                        }
                        let (hit, t0) = slabs(node8, l, &p, near_rows, far_rows, far, active);
                        if hit == 0 {
                            continue;
                        }
                        let t0 = _mm256_blendv_ps(inf, t0, lane_mask(hit));
                        // SAFETY: `Lanes` is 32-byte aligned.
                        unsafe { _mm256_store_ps(entry[l].as_mut_ptr().cast(), t0) };
                        let least = if p.frustum.is_some() { order[l] } else { least_of(t0) };
                        insert_sorted(&mut keys, &mut k, (least.to_bits() & !lane_bits) | l as u32);
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
                    cur_t = unsafe { _mm256_load_ps(entry[l].as_ptr().cast()) };
                    continue 'walk;
                }
            }
        }
        if sp == 0 {
            break;
        }
        sp -= 1;
        // SAFETY: entries below `sp` were written by the pushes above; `Lanes` is aligned.
        (cur, cur_t) = unsafe { (stack_node[sp].assume_init(), _mm256_load_ps(stack_t[sp].assume_init_ref().0.as_ptr())) };
    }
    let lanes = best.store();
    for (r, o) in out.iter_mut().enumerate() {
        *o = Best::hit(&lanes, r);
    }
    true
}

/// The blocks of a leaf against the `active` rays one at a time, with the single-ray
/// block test, from and into their best hits so far.
#[inline]
#[target_feature(enable = "avx2")]
fn few_in_leaf<P: Primitives + ?Sized>(blocks: &[TriBlock], prims: &P, rays: &[Ray], p: &Packet, active: u32, best: &mut Best) {
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
/// `far` limit) and their entry distances, as `slabs_avx2` computes them for each ray.
#[inline]
#[target_feature(enable = "avx2")]
fn slabs(node: &WideNode<8>, l: usize, p: &Packet, near_rows: [usize; 3], far_rows: [usize; 3], far: __m256, active: u32) -> (u32, __m256) {
    let mut t0 = p.t_min;
    let mut t1 = far;
    for a in 0..3 {
        let lo = _mm256_set1_ps(node.bounds[near_rows[a]][l]);
        let hi = _mm256_set1_ps(node.bounds[far_rows[a]][l]);
        let near = _mm256_mul_ps(_mm256_sub_ps(lo, p.origin[a]), p.inv[a]);
        let far = _mm256_mul_ps(_mm256_sub_ps(hi, p.origin[a]), p.inv_far[a]);
        // As in the single-ray kernel: `max(a, b)` returns `b` when either is NaN.
        t0 = _mm256_max_ps(near, t0);
        t1 = _mm256_min_ps(far, t1);
    }
    (bits(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) & active, t0)
}

/// The triangles of block `b` against the `active` rays, updating each ray's best hit; a
/// lane the SIMD arithmetic cannot decide, or that is not a triangle, goes through the
/// exact scalar kernel ray by ray, as in single-ray traversal.
#[inline]
#[target_feature(enable = "avx2")]
fn block<P: Primitives + ?Sized>(b: &TriBlock, prims: &P, rays: &[Ray], p: &Packet, axes: (usize, usize, usize), active: u32, best: &mut Best) {
    for j in 0..4 {
        let prim = b.prim[j];
        if prim == EMPTY {
            continue;
        }
        let zero = _mm256_setzero_ps();
        let (hit, exact, t, u, v) = if prim & TriBlock::OTHER != 0 { (0, active, zero, zero, zero) } else { triangle(b, j, p, axes, active, best.t) };
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
                keep(best, 1 << r, _mm256_set1_ps(x.t), _mm256_set1_ps(x.u), _mm256_set1_ps(x.v), id);
            }
        }
    }
}

/// Makes `(t, prim)` the best hit of the rays in `hit` where it wins: nearer, or as near
/// and a lower primitive (`wins`).
#[inline]
#[target_feature(enable = "avx2")]
fn keep(best: &mut Best, hit: u32, t: __m256, u: __m256, v: __m256, prim: u32) {
    let id = _mm256_set1_epi32(prim as i32);
    // `id < best.prim` as unsigned integers: both with the top bit flipped, as signed.
    let top = _mm256_set1_epi32(i32::MIN);
    let lower = _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_xor_si256(best.prim, top), _mm256_xor_si256(id, top)));
    let nearer = _mm256_cmp_ps::<_CMP_LT_OQ>(t, best.t);
    let tie = _mm256_and_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(t, best.t), lower);
    let win = _mm256_and_ps(lane_mask(hit), _mm256_or_ps(nearer, tie));
    best.t = _mm256_blendv_ps(best.t, t, win);
    best.u = _mm256_blendv_ps(best.u, u, win);
    best.v = _mm256_blendv_ps(best.v, v, win);
    best.prim = _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(best.prim), _mm256_castsi256_ps(id), win));
}

/// Triangle `j` of block `b` against the `active` rays: `triangles_sse`'s operations for
/// one triangle and eight rays. Returns the rays hitting it within `(t_min, t_max]` with
/// `t` and barycentrics, and the rays left to the exact scalar kernel.
#[inline]
#[target_feature(enable = "avx2")]
fn triangle(b: &TriBlock, j: usize, p: &Packet, (kx, ky, kz): (usize, usize, usize), active: u32, t_max: __m256) -> (u32, u32, __m256, __m256, __m256) {
    let [sx, sy, sz] = p.shear;
    let (ox, oy, oz) = (p.origin[kx], p.origin[ky], p.origin[kz]);
    let project = |v: usize| {
        let az = _mm256_sub_ps(_mm256_set1_ps(b.p[v][kz][j]), oz);
        let x = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(b.p[v][kx][j]), ox), _mm256_mul_ps(sx, az));
        let y = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(b.p[v][ky][j]), oy), _mm256_mul_ps(sy, az));
        (x, y, az)
    };
    let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (project(0), project(1), project(2));
    let u = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
    let v = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
    let w = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
    let zero = _mm256_setzero_ps();
    let sign = _mm256_set1_ps(-0.0);
    let abs = |x: __m256| _mm256_andnot_ps(sign, x);
    // Mixed signs: the sign bits differ (`movemask` reads the sign bits).
    let mixed = bits(_mm256_or_ps(_mm256_xor_ps(u, v), _mm256_xor_ps(u, w)));
    let nonzero = bits(_mm256_cmp_ps::<_CMP_GT_OQ>(abs(_mm256_mul_ps(_mm256_mul_ps(u, v), w)), zero));
    if active & !(nonzero & mixed) == 0 {
        return (0, 0, zero, zero, zero);
    }
    let eq0 = |x: __m256| bits(_mm256_cmp_ps::<_CMP_EQ_OQ>(x, zero));
    let undecided_edges = eq0(u) | eq0(v) | eq0(w) | bits(_mm256_cmp_ps::<_CMP_UNORD_Q>(u, v)) | bits(_mm256_cmp_ps::<_CMP_UNORD_Q>(w, w));
    let outside = mixed;
    let det = _mm256_add_ps(_mm256_add_ps(u, v), w);
    let (az, bz, cz) = (_mm256_mul_ps(sz, az), _mm256_mul_ps(sz, bz), _mm256_mul_ps(sz, cz));
    let t_scaled = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(u, az), _mm256_mul_ps(v, bz)), _mm256_mul_ps(w, cz));
    let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
    let t = _mm256_mul_ps(t_scaled, inv_det);
    let max3 = |a: __m256, b: __m256, c: __m256| _mm256_max_ps(_mm256_max_ps(abs(a), abs(b)), abs(c));
    let (max_zt, max_xt, max_yt, max_e) = (max3(az, bz, cz), max3(ax, bx, cx), max3(ay, by, cy), max3(u, v, w));
    let g = |n: u32| _mm256_set1_ps(gamma(n));
    let delta_z = _mm256_mul_ps(g(3), max_zt);
    let delta_x = _mm256_mul_ps(g(5), _mm256_add_ps(max_xt, max_zt));
    let delta_y = _mm256_mul_ps(g(5), _mm256_add_ps(max_yt, max_zt));
    let delta_e = _mm256_mul_ps(_mm256_set1_ps(2.0), _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(g(2), max_xt), max_yt), _mm256_mul_ps(delta_y, max_xt)), _mm256_mul_ps(delta_x, max_yt)));
    let delta_t = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(3.0), _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(g(3), max_e), max_zt), _mm256_mul_ps(delta_e, max_zt)), _mm256_mul_ps(delta_z, max_e))), abs(inv_det));
    let inf = _mm256_set1_ps(f32::INFINITY);
    let finite = bits(_mm256_cmp_ps::<_CMP_LT_OQ>(abs(t), inf)) & bits(_mm256_cmp_ps::<_CMP_LT_OQ>(abs(delta_t), inf));
    let ahead = bits(_mm256_cmp_ps::<_CMP_GT_OQ>(t, delta_t));
    let behind = bits(_mm256_cmp_ps::<_CMP_LT_OQ>(t, _mm256_sub_ps(zero, delta_t)));
    let rejected = !undecided_edges & (outside | eq0(det));
    let decided_t = finite & (ahead | behind);
    let in_range = bits(_mm256_cmp_ps::<_CMP_GT_OQ>(t, p.t_min)) & bits(_mm256_cmp_ps::<_CMP_LE_OQ>(t, t_max));
    let hit = active & !(undecided_edges | rejected) & finite & ahead & in_range;
    let exact = active & (undecided_edges | !(rejected | decided_t));
    (hit, exact, t, _mm256_mul_ps(v, inv_det), _mm256_mul_ps(w, inv_det))
}

#[cfg(test)]
mod tests {
    use raylab_core::{Pcg32, Ray, Vec3};

    use super::super::ray_major::tests::{packets, scene, Mixed};
    use super::super::{node::WideNode, quant::QuantNode, WideBvh};
    use super::RAYS;
    use crate::{binary_for_wide, BuildOptions, Counters};

    fn avx2() -> bool {
        std::is_x86_feature_detected!("avx2")
    }

    /// Every packet, cut into packets of eight, against its rays alone; at least
    /// `min_taken` packets through the ray-major path and `min_hits` hits.
    fn check<N: super::super::node::Layout<8>>(bvh: &WideBvh<8, N>, prims: &Mixed, packets: &[Vec<Ray>], min_taken: usize, min_hits: usize) {
        let (mut taken, mut hits) = (0, 0);
        for (k, rays) in packets.iter().flat_map(|p| p.chunks(RAYS)).enumerate() {
            let mut out = vec![None; rays.len()];
            let mut counted = vec![None; rays.len()];
            let mut c = Counters::default();
            // SAFETY: the caller checked AVX2.
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
            // Eight copies of a ray walk as the ray does alone: eight times its work.
            let copies = [rays[0]; RAYS];
            let (mut c8, mut c1) = (Counters::default(), Counters::default());
            // SAFETY: as above.
            assert!(unsafe { super::closest::<_, 8, N, true>(bvh, prims, &copies, &mut [None; RAYS], &mut c8) });
            super::super::traverse::closest::<_, 8, N, true, true>(bvh, prims, &rays[0], &mut c1);
            assert_eq!((c8.nodes_visited, c8.prim_tests), (8 * c1.nodes_visited, 8 * c1.prim_tests), "packet {k}: copies");
        }
        assert!(taken >= min_taken && hits >= min_hits, "too few packets through the ray-major path: {taken} packets, {hits} hits");
    }

    #[test]
    fn coherent_packets_of_eight_get_their_single_ray_answers() {
        if !avx2() {
            eprintln!("no AVX2 on this CPU: the 8-ray ray-major path is not run");
            return;
        }
        let mut rng = Pcg32::new(11, 3);
        let prims = scene(&mut rng);
        let packets = packets(&mut rng, &prims);
        let binary = binary_for_wide(&prims, &BuildOptions::default(), "bvh");
        check(&WideBvh::<8, WideNode<8>>::from_binary(&binary, &prims, "bvh8"), &prims, &packets, 600, 2000);
        check(&WideBvh::<8, QuantNode>::from_binary(&binary, &prims, "bvh8q"), &prims, &packets, 600, 2000);
    }

    /// A ray with a zero direction component has an infinite inverse: no frustum, and the
    /// packet still gets its single-ray answers.
    #[test]
    fn packets_of_eight_with_an_infinite_inverse_have_no_frustum() {
        if !avx2() {
            return;
        }
        let rays: Vec<Ray> = (0..RAYS).map(|q| Ray::new(Vec3::new(0.01 * q as f32, 0.0, 0.0), Vec3::new(0.0, 0.1, 1.0))).collect();
        // SAFETY: AVX2 checked above.
        assert!(unsafe { super::Packet::new(&rays) }.is_some_and(|(p, _)| p.frustum.is_none()));
        let mut rng = Pcg32::new(5, 7);
        let prims = scene(&mut rng);
        let bvh = WideBvh::<8, WideNode<8>>::from_binary(&binary_for_wide(&prims, &BuildOptions::default(), "bvh"), &prims, "bvh8");
        let packets: Vec<Vec<Ray>> = (0..50).map(|k| (0..RAYS).map(|q| Ray::new(Vec3::new(-0.9 + 0.036 * k as f32, -0.9 + 0.2 * q as f32, -3.0), Vec3::new(0.0, 0.05, 1.0))).collect()).collect();
        check(&bvh, &prims, &packets, 40, 100);
    }

    /// The triangle kernel decides each ray as `triangles_sse` decides that ray alone: the
    /// same hits with the same bits of `t` and barycentrics, and the same rays left to the
    /// scalar kernel. Random, degenerate, tiny and huge triangles, origins on the
    /// triangles and limited `t` ranges.
    #[test]
    fn the_eight_lane_triangle_kernel_matches_the_four_wide_kernel_ray_by_ray() {
        use super::super::kernels::triangles_sse;
        use raylab_core::intersect::ShearedRay;
        if !avx2() {
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
            let rays: Vec<Ray> = (0..RAYS).map(|q| {
                let d = aim + Vec3::new((q % 4) as f32 - 1.5, (q / 4) as f32 - 0.5, 0.0) * 0.01 * aim.length();
                let mut ray = Ray::new(origin, if k % 11 == 0 { -d } else { d });
                if k % 4 == 0 {
                    ray.t_max = 0.9 + 0.01 * q as f32;
                }
                ray
            }).collect();
            // SAFETY: AVX2 checked above.
            let Some((p, t_max)) = (unsafe { super::Packet::new(&rays) }) else { continue };
            packets += 1;
            // SAFETY: as above.
            let t_maxes = unsafe { super::lanes(t_max) };
            for j in 0..4 {
                // SAFETY: as above.
                let (hit, ex, t, u, v) = unsafe { super::triangle(&b, j, &p, p.axes, super::ALL, t_max) };
                // SAFETY: as above.
                let (t, u, v) = unsafe { (super::lanes(t), super::lanes(u), super::lanes(v)) };
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
        assert!(packets > 3000 && hits > 5000 && exact > 500, "too few cases: {packets} packets, {hits} hits, {exact} left to the scalar kernel");
    }

    /// The frustum of eight rays keeps every child that any of them enters, with an entry
    /// distance no greater than that ray's: random boxes (empty, flat, huge and tiny ones
    /// among them) against packets over narrow and wide cones, some from scattered origins.
    #[test]
    fn the_frustum_of_eight_rays_keeps_every_child_they_enter() {
        use super::super::kernels::{slabs_avx2, RayBoxes};
        if !avx2() {
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
            let rays: Vec<Ray> = (0..RAYS).map(|q| {
                let o = if k % 4 == 0 { origin + r() * 0.5 * scale } else { origin };
                let mut ray = Ray::new(o, aim + Vec3::new((q % 4) as f32 - 1.5, (q / 4) as f32 - 0.5, 0.0) * spread * 0.1);
                ray.t_min = if k % 5 == 0 { 0.1 * q as f32 } else { 0.0 };
                ray.t_max = if k % 6 == 0 { 1.0 + q as f32 } else { f32::INFINITY };
                ray
            }).collect();
            // SAFETY: AVX2 checked above.
            let Some((p, t_max)) = (unsafe { super::Packet::new(&rays) }) else { continue };
            let f = p.frustum.as_ref().expect("finite constants give a frustum");
            packets += 1;
            let far_each = t_max_far(t_max);
            let far_max = far_each.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            // SAFETY: as above.
            let (kept, t0) = unsafe { super::super::ray_major::frustum_slabs(&node, f, p.near_rows, p.far_rows, far_max) };
            // SAFETY: as above.
            let bound = unsafe { super::lanes(t0) };
            let mut any = 0u32;
            for (q, &far_q) in far_each.iter().enumerate() {
                // SAFETY: as above.
                let (near, exit) = unsafe {
                    let (n, x) = slabs_avx2(&node, &RayBoxes::new(&rays[q]), far_q);
                    (super::lanes(n), super::lanes(x))
                };
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

    /// Each ray's far limit for box tests (`t_max · ROBUST_FAR`, as the walk computes it).
    fn t_max_far(t_max: core::arch::x86_64::__m256) -> [f32; RAYS] {
        // SAFETY: the callers checked AVX2.
        unsafe { super::lanes(t_max) }.map(|t| t * super::ROBUST_FAR)
    }

    /// The packet's constants, loaded by the transpose, are each ray's own (`RayBoxes::new`,
    /// `ShearedRay::new`) and their exact extremes, for packets of 1 to 8 rays (lanes past
    /// the count repeat the last ray).
    #[test]
    fn packet_of_eight_constants_are_each_rays_own_and_their_extremes() {
        use super::super::kernels::RayBoxes;
        use raylab_core::intersect::ShearedRay;
        if !avx2() {
            return;
        }
        let mut rng = Pcg32::new(3, 9);
        let mut f = |s: f32| (rng.next_f32() - 0.5) * s;
        let mut taken = 0;
        for k in 0..400 {
            let n = 1 + k % RAYS;
            let rays: Vec<Ray> = (0..n).map(|_| Ray::segment(Vec3::new(f(8.0), f(8.0), f(8.0)), Vec3::new(0.3 + f(0.2), -0.2 + f(0.2), 1.0 + f(0.4)), f(0.1).abs(), 5.0 + f(4.0))).collect();
            // SAFETY: AVX2 checked above.
            let Some((p, t_max)) = (unsafe { super::Packet::new(&rays) }) else { continue };
            taken += 1;
            let fr = p.frustum.as_ref().expect("finite constants");
            // SAFETY: as above.
            let lanes = |x: core::arch::x86_64::__m256| unsafe { super::lanes(x) };
            for r in 0..RAYS {
                let ray = &rays[r.min(n - 1)];
                let (rb, sh) = (RayBoxes::new(ray), ShearedRay::new(ray));
                let bits = |x: &[f32]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                let got = |xs: &[core::arch::x86_64::__m256]| xs.iter().map(|&x| lanes(x)[r]).collect::<Vec<_>>();
                assert_eq!(bits(&got(&p.origin)), bits(&rb.origin), "packet {k} ray {r}: origin");
                assert_eq!(bits(&got(&p.inv)), bits(&rb.inv), "packet {k} ray {r}: inverse");
                assert_eq!(bits(&got(&p.inv_far)), bits(&rb.inv_far), "packet {k} ray {r}: inverse for far planes");
                assert_eq!(bits(&got(&p.shear)), bits(&[sh.sx, sh.sy, sh.sz]), "packet {k} ray {r}: shear");
                assert_eq!((lanes(p.t_min)[r], lanes(t_max)[r]), (rb.t_min, ray.t_max), "packet {k} ray {r}: interval");
                assert_eq!(p.axes, (sh.kx, sh.ky, sh.kz), "packet {k}: shear axes");
                assert_eq!((p.near_rows, p.far_rows), (rb.near, rb.far), "packet {k}: box rows");
                assert_eq!(p.sheared(r).origin, ray.origin, "packet {k} ray {r}: stored origin");
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

    #[test]
    fn packets_of_eight_of_mixed_octants_or_axes_are_declined() {
        if !avx2() {
            return;
        }
        let prims = Mixed::one_triangle();
        let bvh = WideBvh::<8, WideNode<8>>::from_binary(&binary_for_wide(&prims, &BuildOptions::default(), "bvh"), &prims, "bvh8");
        let run = |dirs: &[Vec3]| {
            let rays: Vec<Ray> = dirs.iter().map(|&d| Ray::new(Vec3::ZERO, d)).collect();
            let mut out = vec![None; rays.len()];
            // SAFETY: AVX2 checked above.
            let took = unsafe { super::closest::<_, 8, WideNode<8>, false>(&bvh, &prims, &rays, &mut out, &mut Counters::default()) };
            (took, out)
        };
        let (took, out) = run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(0.2, 0.1, 1.0)]);
        assert!(took);
        assert_eq!(out.iter().map(|h| h.map(|h| (h.prim, h.t))).collect::<Vec<_>>(), [Some((0, 2.0)); 2]);
        assert!(!run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(-0.1, 0.1, 1.0)]).0);
        assert!(!run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(2.0, 0.1, 1.0)]).0);
        assert!(!run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(0.1, 0.1, -1.0)]).0);
    }
}
