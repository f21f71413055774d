//! Closest hits of a packet of up to [`PACKET`] rays (a 4×4 tile of camera rays) through
//! a wide BVH: the packet walks the tree together, each stack entry carrying the mask of
//! rays that entered the child, so a node is loaded once for all the rays that reach it
//! and the stack, the ordering and the loop run once per packet instead of once per ray.
//!
//! Each active ray tests a node's `W` child boxes with the single-ray kernel (AVX2 or
//! portable), and each candidate triangle with the same exact kernel, so the answers are
//! those of single-ray traversal bit for bit: hits are kept as the least `(t, prim)`
//! (see [`super::traverse::wins`]), which does not depend on the order of the tests, and
//! a ray's box tests are as conservative as when it travels alone.

use std::mem::MaybeUninit;

use raylab_core::intersect::ShearedRay;
use raylab_core::Ray;

#[cfg(target_arch = "x86_64")]
use super::kernels::{child_boxes, slabs_avx2, slabs_of_rows_avx2};
use super::ray::{BlockRay, RayBoxes, ROBUST_FAR};
use super::node::{is_leaf, ChildRef, Layout, WideNode, EMPTY};
use super::traverse::{block_closest, insert_sorted, leaf_slice, occupied, prefetch, STACK};
use super::WideBvh;
use crate::{Counters, Hit, Primitives};

/// Rays per packet: a 4×4 tile, one bit each in a [`RayMask`].
pub const PACKET: usize = 16;

/// Bit `r` set: ray `r` of the packet is active.
type RayMask = u32;

#[derive(Clone, Copy)]
struct Entry {
    node: ChildRef,
    rays: RayMask,
    /// The least entry distance of those rays.
    t: f32,
}

/// Iterates over the set bits of a mask, lowest first.
#[inline(always)]
fn bits(mut m: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let b = m.trailing_zeros() as usize;
            m &= m - 1;
            b
        })
    })
}

/// Tests the children of `node` against the `active` rays: `entered[l]` gets the rays
/// entering child `l`, `nearest[l]` their least entry distance; returns the children
/// entered by any ray.
#[inline(always)]
fn node_boxes<const W: usize, const SIMD: bool>(node: &WideNode<W>, rb: &[RayBoxes; PACKET], rows: Option<Rows>, far: &[f32; PACKET], active: RayMask, entered: &mut [RayMask; W], nearest: &mut [f32; W]) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if SIMD && W == 8 {
        // SAFETY: `W == 8`, so these are the same types; SIMD = true with W = 8 is only
        // instantiated inside functions with AVX2 enabled (`packet_avx2`, `packet_avx512`)
        // that `Kernel::available` selects after detecting their features.
        return unsafe {
            node_boxes_avx2(&*(node as *const WideNode<W>).cast::<WideNode<8>>(), rb, rows, far, active, &mut *(entered as *mut [RayMask; W]).cast::<[RayMask; 8]>(), &mut *(nearest as *mut [f32; W]).cast::<[f32; 8]>())
        };
    }
    let mut any = 0u32;
    for r in bits(active) {
        let mut tnear = [0.0f32; W];
        let m = child_boxes::<W, SIMD>(node, &rb[r], far[r], &mut tnear);
        any |= m;
        for l in bits(m) {
            entered[l] |= 1 << r;
            nearest[l] = nearest[l].min(tnear[l]);
        }
    }
    any
}

/// The node-bound rows of each axis's near and far planes (`RayBoxes::near`, `far`), when
/// every ray of the packet has the same direction signs.
type Rows = ([usize; 3], [usize; 3]);

#[inline(always)]
fn shared_rows(rb: &[RayBoxes; PACKET]) -> Option<Rows> {
    rb.iter().all(|r| r.near == rb[0].near).then_some((rb[0].near, rb[0].far))
}

/// [`node_boxes`] for 8-wide nodes with AVX2: each ray's slab test as in single-ray
/// traversal ([`slabs_avx2`]), its hit lanes or-ed into the children's ray masks and its
/// entry distances min-ed into theirs in registers, with no per-lane loop. When the rays
/// share their direction signs (`rows`), the node's six planes are loaded once for all.
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn node_boxes_avx2(node: &WideNode<8>, rb: &[RayBoxes; PACKET], rows: Option<Rows>, far: &[f32; PACKET], active: RayMask, entered: &mut [RayMask; 8], nearest: &mut [f32; 8]) -> u32 {
    use std::arch::x86_64::*;
    let mut rays = _mm256_setzero_si256();
    let mut near = _mm256_set1_ps(f32::INFINITY);
    let mut add = |r: usize, t0: __m256, t1: __m256| {
        let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1);
        rays = _mm256_or_si256(rays, _mm256_and_si256(_mm256_castps_si256(hit), _mm256_set1_epi32(1 << r)));
        // Entry distances are never NaN (the slab test's `max` keeps `t_min` over a NaN).
        near = _mm256_min_ps(near, _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), t0, hit));
    };
    if let Some((near_rows, far_rows)) = rows {
        // SAFETY: each row holds 8 f32.
        let load = |row: usize| unsafe { _mm256_loadu_ps(node.bounds[row].as_ptr()) };
        let lo = near_rows.map(load);
        let hi = far_rows.map(load);
        for r in bits(active) {
            // SAFETY: AVX2 is enabled in this function.
            let (t0, t1) = unsafe { slabs_of_rows_avx2(&lo, &hi, &rb[r], far[r]) };
            add(r, t0, t1);
        }
    } else {
        for r in bits(active) {
            // SAFETY: AVX2 is enabled in this function.
            let (t0, t1) = unsafe { slabs_avx2(node, &rb[r], far[r]) };
            add(r, t0, t1);
        }
    }
    // SAFETY: both arrays hold 8 lanes of 4 bytes.
    unsafe {
        _mm256_storeu_si256(entered.as_mut_ptr().cast(), rays);
        _mm256_storeu_ps(nearest.as_mut_ptr(), near);
    }
    // Ray masks are below 2^16, so "non-zero" is "greater than zero".
    _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(rays, _mm256_setzero_si256()))) as u32
}

/// The rays of `rays` whose far limit is at least `t`, four compares at a time.
#[inline(always)]
fn reaching<const SIMD: bool>(t: f32, far: &Far, rays: RayMask) -> RayMask {
    #[cfg(target_arch = "x86_64")]
    if SIMD {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is in the x86-64 baseline; `Far` is 16-byte aligned and holds 16 f32.
        return unsafe {
            let t = _mm_set1_ps(t);
            let m = |i: usize| _mm_movemask_ps(_mm_cmple_ps(t, _mm_load_ps(far.0.as_ptr().add(4 * i)))) as u32;
            (m(0) | m(1) << 4 | m(2) << 8 | m(3) << 12) & rays
        };
    }
    let mut alive = 0;
    for r in bits(rays) {
        alive |= RayMask::from(t <= far.0[r]) << r;
    }
    alive
}

/// Each ray's far limit for box tests, aligned for SIMD loads.
#[repr(C, align(16))]
struct Far([f32; PACKET]);

/// Closest hits of `rays` (at most [`PACKET`]) into `out` (as long as `rays`). The counting
/// build (`COUNT`) charges each ray the nodes it is active in and the occupied triangle
/// lanes it tests: a node loaded once for the packet counts once per ray that needed it,
/// as it would alone.
#[inline(always)]
pub(super) fn closest<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const SIMD: bool, const COUNT: bool>(bvh: &WideBvh<W, N>, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) {
    let n = rays.len();
    assert!(n <= PACKET && out.len() == n, "a packet holds at most {PACKET} rays and as many answers");
    out.fill(None);
    if COUNT {
        c.rays += n as u64;
    }
    if bvh.root == EMPTY || n == 0 {
        return;
    }
    // Lanes past `n` repeat the last ray and are never active.
    let mut ray: [Ray; PACKET] = std::array::from_fn(|r| rays[r.min(n - 1)]);
    let rb: [RayBoxes; PACKET] = std::array::from_fn(|r| RayBoxes::new(&ray[r]));
    let sheared: [ShearedRay; PACKET] = std::array::from_fn(|r| ShearedRay::new(&ray[r]));
    // Each ray's far limit for box tests, widened as in single-ray traversal.
    let mut far = Far(std::array::from_fn(|r| ray[r].t_max * ROBUST_FAR));
    let rows = shared_rows(&rb);
    let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = bvh.root;
    let mut active: RayMask = (1 << n) - 1;
    'walk: loop {
        if COUNT {
            c.nodes_visited += u64::from(active.count_ones());
        }
        if is_leaf(cur) {
            for b in leaf_slice(bvh, cur) {
                if COUNT {
                    c.prim_tests += occupied(b) * u64::from(active.count_ones());
                }
                for r in bits(active) {
                    block_closest::<P, SIMD>(b, prims, &sheared[r], &BlockRay::new(&sheared[r]), &mut ray[r], &mut out[r]);
                    far.0[r] = ray[r].t_max * ROBUST_FAR;
                }
            }
        } else {
            let node = bvh.node(cur);
            // Per child: the rays entering it and their least entry distance.
            let mut entered = [0 as RayMask; W];
            let mut nearest = [f32::INFINITY; W];
            // A quantised node is decoded once for the whole packet.
            let any = node.with_decoded(|n| node_boxes::<W, SIMD>(n, &rb, rows, &far.0, active, &mut entered, &mut nearest));
            if any != 0 {
                if any & (any - 1) == 0 {
                    let l = any.trailing_zeros() as usize;
                    cur = node.child(l);
                    active = entered[l];
                    continue 'walk;
                }
                // Nearest child first, as in single-ray traversal (keys: distance bits
                // with the lane in the low bits); two children without a sort.
                let lane_bits = W as u32 - 1;
                let key = |l: usize| (nearest[l].to_bits() & !lane_bits) | l as u32;
                let rest = any & (any - 1);
                if rest & (rest - 1) == 0 {
                    let (first, second) = (any.trailing_zeros() as usize, rest.trailing_zeros() as usize);
                    let (near, far) = if key(second) < key(first) { (second, first) } else { (first, second) };
                    prefetch(bvh, node.child(far));
                    stack[sp] = MaybeUninit::new(Entry { node: node.child(far), rays: entered[far], t: nearest[far] });
                    sp += 1;
                    cur = node.child(near);
                    active = entered[near];
                    continue 'walk;
                }
                let mut keys = [0u32; W];
                let mut k = 0;
                for l in bits(any) {
                    insert_sorted(&mut keys, &mut k, key(l));
                }
                for &key in keys[1..k].iter().rev() {
                    let l = (key & lane_bits) as usize;
                    prefetch(bvh, node.child(l));
                    stack[sp] = MaybeUninit::new(Entry { node: node.child(l), rays: entered[l], t: nearest[l] });
                    sp += 1;
                }
                let l = (keys[0] & lane_bits) as usize;
                cur = node.child(l);
                active = entered[l];
                continue 'walk;
            }
        }
        while sp > 0 {
            sp -= 1;
            // SAFETY: entries below `sp` were written by the pushes above.
            let e = unsafe { stack[sp].assume_init() };
            // Rays whose hit so far is nearer than every entry into the child drop out.
            let alive = reaching::<SIMD>(e.t, &far, e.rays);
            if alive != 0 {
                cur = e.node;
                active = alive;
                continue 'walk;
            }
        }
        break;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raylab_core::Vec3;

    #[test]
    fn reaching_keeps_the_rays_whose_far_limit_is_at_least_t() {
        // Ray r's far limit is r, ray 15's is NaN (a limit no distance reaches).
        let mut far = Far(std::array::from_fn(|r| r as f32));
        far.0[15] = f32::NAN;
        let every: RayMask = 0xFFFF;
        // t = 5: rays 5..=14 reach it (5 <= 5 included), NaN does not.
        let want = 0b0111_1111_1110_0000;
        assert_eq!(reaching::<false>(5.0, &far, every), want);
        // Only the rays asked about: 1, 6 and 12 of which 6 and 12 reach.
        assert_eq!(reaching::<false>(5.0, &far, 1 << 1 | 1 << 6 | 1 << 12), 1 << 6 | 1 << 12);
        assert_eq!(reaching::<false>(-1.0, &far, every), 0x7FFF);
        assert_eq!(reaching::<false>(f32::INFINITY, &far, every), 0);
        #[cfg(target_arch = "x86_64")]
        for (t, rays) in [(5.0, every), (5.0, 1 << 1 | 1 << 6 | 1 << 12), (-1.0, every), (f32::INFINITY, every), (14.0, 0b1100_0000_0000_0001), (3.5, 0b1010_1010_1010_1010)] {
            assert_eq!(reaching::<true>(t, &far, rays), reaching::<false>(t, &far, rays), "t = {t}, rays = {rays:#x}");
        }
        assert_eq!(reaching::<true>(14.0, &far, 0b1100_0000_0000_0001), 1 << 14);
    }

    #[test]
    fn rows_are_shared_only_by_rays_of_one_octant() {
        let boxes = |dirs: &[Vec3]| -> [RayBoxes; PACKET] { std::array::from_fn(|r| RayBoxes::new(&Ray::new(Vec3::ZERO, dirs[r % dirs.len()]))) };
        // +x, -y, +z: near planes min x (row 0), max y (row 4), min z (row 2).
        let rb = boxes(&[Vec3::new(1.0, -1.0, 1.0), Vec3::new(0.5, -2.0, 0.1)]);
        assert_eq!(shared_rows(&rb), Some(([0, 4, 2], [3, 1, 5])));
        // One ray of sixteen turned towards -z: the rows differ.
        let mut rb = rb;
        rb[9] = RayBoxes::new(&Ray::new(Vec3::ZERO, Vec3::new(1.0, -1.0, -1.0)));
        assert_eq!(shared_rows(&rb), None);
    }
}
