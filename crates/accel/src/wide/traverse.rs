//! Closest-hit and any-hit traversal of a wide BVH, generic over the width, the kernel
//! (SIMD or portable), whether work is counted and whether children are prefetched
//! ([`Prefetch`](super::Prefetch)): const flags, so the fast path carries no counter code
//! and a walk that does not prefetch no test of whether it should.
//!
//! The stack holds `(node, entry distance)` pairs and is never cleared: a pop whose entry
//! lies beyond the current closest hit is dropped without touching the node's memory.
//! Children are pushed far to near by their entry distance (the key's low bits hold the
//! lane, Embree's trick), so the nearest is entered first and shrinks `t_max` early.

use std::mem::MaybeUninit;

use raylab_core::intersect::ShearedRay;
use raylab_core::Ray;

use super::kernels::triangle_candidates;
use super::ray::{BlockRay, RayBoxes, ROBUST_FAR};

use super::node::{is_leaf, leaf_blocks, ChildRef, Layout, TriBlock, EMPTY};
use super::WideBvh;
use crate::{Counters, Hit, PrimHit, Primitives};

/// Stack entries: at most `W - 1` pushes per level and trees at most `MAX_DEPTH + 1`
/// wide levels deep (a wide level consumes at least one binary level; a split leaf adds
/// one), so `65 · 7 = 455` entries suffice for `W = 8`.
pub(super) const STACK: usize = 512;

/// `repr(C)`: the AVX2 push ([`push_sorted_avx2`]) writes entries as pairs of 32-bit lanes.
#[derive(Clone, Copy)]
#[repr(C)]
struct Entry {
    node: ChildRef,
    t: f32,
}

/// Work counted by the counting build, kept in registers and added once per ray.
#[derive(Default)]
struct Work {
    nodes: u64,
    tests: u64,
}

/// Whether a hit at `t` on `prim`, found with `t <= ray.t_max` (the current best's
/// distance), replaces `best`: a nearer one does, and a tie goes to the lower primitive
/// index. The answer is then the least `(t, prim)` over the primitives hit, whatever the
/// order in which they were tested, so that packet traversal (another order) returns the
/// same primitive as single-ray traversal on shared edges and coplanar overlaps.
#[inline(always)]
pub(super) fn wins(t: f32, prim: u32, best: &Option<Hit>) -> bool {
    best.is_none_or(|b| t < b.t || prim < b.prim)
}

/// The closest hit among the lanes of block `b`, if nearer than `best` (ties to the lower
/// primitive); moves `ray.t_max` to it. With SIMD the four triangles are tested at once
/// ([`triangles_sse`](super::kernels::triangles_sse)) and only the lanes it cannot decide
/// take a call.
#[inline(always)]
pub(super) fn block_closest<P: Primitives + ?Sized, const SIMD: bool>(b: &TriBlock, prims: &P, s: &ShearedRay, br: &BlockRay, ray: &mut Ray, best: &mut Option<Hit>) {
    #[cfg(target_arch = "x86_64")]
    if SIMD {
        let Some(h) = super::kernels::block_hits_sse(b, br, ray.t_min, ray.t_max) else {
            return;
        };
        let mut m = h.hit | h.exact;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let found = if h.hit & (1 << l) != 0 { Some(PrimHit { t: h.t[l], u: h.u[l], v: h.v[l] }) } else { exact_lane(b, l, prims, s, ray) };
            let prim = b.prim[l] & !TriBlock::OTHER;
            // Lanes were tested against the `t_max` the block started with.
            if let Some(x) = found.filter(|x| x.t <= ray.t_max && wins(x.t, prim, best)) {
                ray.t_max = x.t;
                *best = Some(Hit::new(prim, x));
            }
        }
        return;
    }
    let mut m = triangle_candidates(b, s);
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        let prim = b.prim[l] & !TriBlock::OTHER;
        if let Some(x) = exact_lane(b, l, prims, s, ray).filter(|x| wins(x.t, prim, best)) {
            ray.t_max = x.t;
            *best = Some(Hit::new(prim, x));
        }
    }
}

/// Whether any lane of block `b` is hit (see [`block_closest`]).
#[inline(always)]
fn block_any<P: Primitives + ?Sized, const SIMD: bool>(b: &TriBlock, prims: &P, s: &ShearedRay, br: &BlockRay, ray: &Ray) -> bool {
    #[cfg(target_arch = "x86_64")]
    let mut m = if SIMD {
        let Some(h) = super::kernels::block_hits_sse(b, br, ray.t_min, ray.t_max) else {
            return false;
        };
        if h.hit != 0 {
            return true;
        }
        h.exact
    } else {
        triangle_candidates(b, s)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let mut m = triangle_candidates(b, s);
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        if exact_lane(b, l, prims, s, ray).is_some() {
            return true;
        }
    }
    false
}

/// Lane `l` of `b` through the scalar kernel: the watertight triangle test with its
/// double-precision fallbacks, or the primitive's own test. Kept out of line: the
/// traversal's registers are spilled only on this (with SIMD, rare) path.
#[inline(never)]
pub(super) fn exact_lane<P: Primitives + ?Sized>(b: &TriBlock, l: usize, prims: &P, s: &ShearedRay, ray: &Ray) -> Option<PrimHit> {
    let p = b.prim[l];
    if p & TriBlock::OTHER != 0 {
        prims.intersect(p & !TriBlock::OTHER, ray)
    } else {
        s.triangle(ray.t_min, ray.t_max, b.vertex(l, 0), b.vertex(l, 1), b.vertex(l, 2)).map(|(t, u, v)| PrimHit { t, u, v })
    }
}

/// Inserts `key` into the ascending `keys[..*n]` and counts it: an insertion sort of a
/// node's entered children (at most `W` keys of entry distance bits and lane).
#[inline(always)]
pub(super) fn insert_sorted<const W: usize>(keys: &mut [u32; W], n: &mut usize, key: u32) {
    let mut k = *n;
    while k > 0 && keys[k - 1] > key {
        keys[k] = keys[k - 1];
        k -= 1;
    }
    keys[k] = key;
    *n += 1;
}

/// Occupied lanes of a block (what the counting build charges as primitive tests).
#[inline(always)]
pub(super) fn occupied(b: &TriBlock) -> u64 {
    b.prim.iter().filter(|&&p| p != EMPTY).count() as u64
}

/// Closest hit among the blocks of a leaf; moves `ray.t_max` to each hit found.
#[inline(always)]
fn leaf_closest<P: Primitives + ?Sized, const SIMD: bool, const COUNT: bool>(blocks: &[TriBlock], prims: &P, s: &ShearedRay, br: &BlockRay, ray: &mut Ray, best: &mut Option<Hit>, w: &mut Work) {
    for b in blocks {
        if COUNT {
            w.tests += occupied(b);
        }
        block_closest::<P, SIMD>(b, prims, s, br, ray, best);
    }
}

/// Whether anything in the blocks of a leaf is hit; stops at the first.
#[inline(always)]
fn leaf_any<P: Primitives + ?Sized, const SIMD: bool, const COUNT: bool>(blocks: &[TriBlock], prims: &P, s: &ShearedRay, br: &BlockRay, ray: &Ray, w: &mut Work) -> bool {
    for b in blocks {
        if COUNT {
            w.tests += occupied(b);
        }
        if block_any::<P, SIMD>(b, prims, s, br, ray) {
            return true;
        }
    }
    false
}

#[inline(always)]
pub(super) fn leaf_slice<const W: usize, N: Layout<W>>(bvh: &WideBvh<W, N>, r: ChildRef) -> &[TriBlock] {
    let (first, n) = leaf_blocks(r);
    &bvh.blocks[first..first + n]
}

/// Starts loading a child's node or first block, all its cache lines: a pushed child is
/// popped after its nearer siblings' subtrees, and an entered node's child references sit
/// in its last line, read only once its box test is done.
#[inline(always)]
pub(super) fn prefetch<const W: usize, N: Layout<W>>(bvh: &WideBvh<W, N>, r: ChildRef) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let (p, bytes) = if is_leaf(r) { ((&bvh.blocks[super::node::leaf_blocks(r).0] as *const TriBlock).cast::<i8>(), std::mem::size_of::<TriBlock>()) } else { ((bvh.node(r) as *const N).cast::<i8>(), std::mem::size_of::<N>()) };
        // One prefetch per 64 bytes from the element's start (a last line it may reach
        // into is left out: prefetching it measured no faster).
        for line in (0..bytes).step_by(64) {
            // SAFETY: a prefetch never faults; the addresses are within the element.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(line)) };
        }
    }
}

/// The portable walk of the rare rays the SIMD walk hands over, out of line so that it
/// does not share the SIMD walk's function and registers.
#[inline(never)]
fn closest_portable<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool>(bvh: &WideBvh<W, N>, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
    closest::<P, W, N, false, COUNT, false>(bvh, prims, ray, c)
}

#[inline(never)]
fn any_portable<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool>(bvh: &WideBvh<W, N>, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
    any::<P, W, N, false, COUNT, false>(bvh, prims, ray, c)
}

/// The children of interior node `cur` that the ray enters within `t_max`: pushes all but
/// the nearest, far to near, and returns the nearest; `None` when it enters none.
#[inline(always)]
fn enter_closest<const W: usize, N: Layout<W>, const SIMD: bool, const PF: bool>(bvh: &WideBvh<W, N>, cur: ChildRef, rb: &RayBoxes, t_max: f32, stack: &mut [MaybeUninit<Entry>; STACK], sp: &mut usize) -> Option<ChildRef> {
    let node = bvh.node(cur);
    let mut tnear = [0.0f32; W];
    let mask = node.boxes::<SIMD>(rb, t_max * ROBUST_FAR, &mut tnear);
    if mask == 0 {
        return None;
    }
    let first = mask.trailing_zeros() as usize;
    if mask & (mask - 1) == 0 {
        return Some(entered::<W, N, PF>(bvh, node.child(first)));
    }
    let rest = mask & (mask - 1);
    if rest & (rest - 1) == 0 {
        // Two children, the most frequent case after one: no sort, the same order as the
        // keys below give.
        let second = rest.trailing_zeros() as usize;
        let key = |l: usize| (tnear[l].to_bits() & !(W as u32 - 1)) | l as u32;
        let (near, far) = if key(second) < key(first) { (second, first) } else { (first, second) };
        push::<W, N, PF>(bvh, stack, sp, Entry { node: node.child(far), t: tnear[far] });
        return Some(entered::<W, N, PF>(bvh, node.child(near)));
    }
    #[cfg(target_arch = "x86_64")]
    if SIMD && W == 8 {
        // SAFETY: as in `child_boxes`: SIMD = true with W = 8 is only instantiated inside
        // functions with AVX2 enabled, selected after detecting it; `tnear` has 8 lanes.
        let (nearest, pushed) = unsafe { push_sorted_avx2(&*(&tnear as *const [f32; W]).cast::<[f32; 8]>(), mask, std::array::from_fn(|l| node.child(l)), stack, sp) };
        if PF {
            for e in &stack[*sp - pushed..*sp] {
                // SAFETY: just written by `push_sorted_avx2`.
                prefetch(bvh, unsafe { e.assume_init() }.node);
            }
        }
        return Some(entered::<W, N, PF>(bvh, nearest));
    }
    // Sort the hit lanes by entry distance: keys are the distance's bits (in order for
    // t >= 0) with the lane in the low bits.
    let lane_bits = W as u32 - 1;
    let mut keys = [0u32; W];
    let mut n = 0;
    let mut m = mask;
    while m != 0 {
        let l = m.trailing_zeros();
        m &= m - 1;
        insert_sorted(&mut keys, &mut n, (tnear[l as usize].to_bits() & !lane_bits) | l);
    }
    for &key in keys[1..n].iter().rev() {
        let l = (key & lane_bits) as usize;
        push::<W, N, PF>(bvh, stack, sp, Entry { node: node.child(l), t: tnear[l] });
    }
    Some(entered::<W, N, PF>(bvh, node.child((keys[0] & lane_bits) as usize)))
}

/// The three or more children of `mask` sorted as the insertion sort of [`enter_closest`]
/// sorts them (keys of entry distance bits and lane), without a branch: a bitonic network
/// on eight keys (lanes not entered sort last as `u32::MAX`), then one permutation that
/// puts all but the nearest far to near, and two stores of eight entries at `sp` (the
/// ones beyond the new top are left there unread). Returns the nearest child and how many
/// were pushed. Embree sorts three and four children with networks too; the insertion
/// sort took about 150 instructions and some mispredicted branches per such node.
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn push_sorted_avx2(tnear: &[f32; 8], mask: u32, child: [ChildRef; 8], stack: &mut [MaybeUninit<Entry>; STACK], sp: &mut usize) -> (ChildRef, usize) {
    use std::arch::x86_64::*;
    let iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    // SAFETY: `tnear` and `child` hold 8 lanes of 32 bits.
    let t = unsafe { _mm256_loadu_si256(tnear.as_ptr().cast()) };
    let keys = _mm256_or_si256(_mm256_and_si256(t, _mm256_set1_epi32(!7)), iota);
    let bit = _mm256_sllv_epi32(_mm256_set1_epi32(1), iota);
    let entered = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(mask as i32), bit), bit);
    let mut v = _mm256_blendv_epi8(_mm256_set1_epi32(-1), keys, entered);
    // Bitonic steps (block size k, distance j): lane i keeps the larger key of the pair
    // (i, i ^ j) where bit i of the blend mask is set, `((i & j) == 0) != ((i & k) == 0)`.
    macro_rules! step {
        ($partner:expr, $max_lanes:literal) => {{
            let p = $partner;
            v = _mm256_blend_epi32::<$max_lanes>(_mm256_min_epu32(v, p), _mm256_max_epu32(v, p));
        }};
    }
    step!(_mm256_shuffle_epi32::<0xB1>(v), 0x66); // k = 2, j = 1
    step!(_mm256_shuffle_epi32::<0x4E>(v), 0x3C); // k = 4, j = 2
    step!(_mm256_shuffle_epi32::<0xB1>(v), 0x5A); // k = 4, j = 1
    step!(_mm256_permute2x128_si256::<0x01>(v, v), 0xF0); // k = 8, j = 4
    step!(_mm256_shuffle_epi32::<0x4E>(v), 0xCC); // k = 8, j = 2
    step!(_mm256_shuffle_epi32::<0xB1>(v), 0xAA); // k = 8, j = 1
    let n = mask.count_ones() as i32;
    // Far to near: entry i is key n - 1 - i (mod 8: the keys past n are not entered).
    let order = _mm256_permutevar8x32_epi32(v, _mm256_and_si256(_mm256_sub_epi32(_mm256_set1_epi32(n - 1), iota), _mm256_set1_epi32(7)));
    let lanes = _mm256_and_si256(order, _mm256_set1_epi32(7));
    // SAFETY: as above.
    let refs = _mm256_permutevar8x32_epi32(unsafe { _mm256_loadu_si256(child.as_ptr().cast()) }, lanes);
    let ts = _mm256_permutevar8x32_epi32(t, lanes);
    let (lo, hi) = (_mm256_unpacklo_epi32(refs, ts), _mm256_unpackhi_epi32(refs, ts));
    assert!(*sp + 8 <= STACK, "traversal stack overflow");
    // SAFETY: entries `sp..sp + 8` are within the stack; `Entry` is two 32-bit fields.
    unsafe {
        let at = stack.as_mut_ptr().add(*sp).cast::<__m256i>();
        _mm256_storeu_si256(at, _mm256_permute2x128_si256::<0x20>(lo, hi));
        _mm256_storeu_si256(at.add(1), _mm256_permute2x128_si256::<0x31>(lo, hi));
    }
    let pushed = n as usize - 1;
    *sp += pushed;
    (child[(_mm256_cvtsi256_si32(v) & 7) as usize], pushed)
}

/// The child entered next, prefetched with `PF`.
#[inline(always)]
fn entered<const W: usize, N: Layout<W>, const PF: bool>(bvh: &WideBvh<W, N>, r: ChildRef) -> ChildRef {
    if PF {
        prefetch(bvh, r);
    }
    r
}

/// Pushes `e`, prefetching its node or block with `PF` ([`Prefetch`](super::Prefetch)).
#[inline(always)]
fn push<const W: usize, N: Layout<W>, const PF: bool>(bvh: &WideBvh<W, N>, stack: &mut [MaybeUninit<Entry>; STACK], sp: &mut usize, e: Entry) {
    if PF {
        prefetch(bvh, e.node);
    }
    stack[*sp] = MaybeUninit::new(e);
    *sp += 1;
}

/// The next pushed node whose entry lies within `t_max` (the others are dropped without
/// touching their memory); `None` when the stack runs out.
#[inline(always)]
fn pop_closest(stack: &[MaybeUninit<Entry>; STACK], sp: &mut usize, t_max: f32) -> Option<ChildRef> {
    while *sp > 0 {
        *sp -= 1;
        // SAFETY: entries below `sp` were written by `enter_closest`.
        let e = unsafe { stack[*sp].assume_init() };
        // Widened as in the box test (see `boxes_portable`).
        if e.t <= t_max * ROBUST_FAR {
            return Some(e.node);
        }
    }
    None
}

#[inline(always)]
pub(super) fn closest<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const SIMD: bool, const COUNT: bool, const PF: bool>(bvh: &WideBvh<W, N>, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
    // The per-ray constants are read from the caller's ray, not from the copy below: a
    // load of a few lanes out of a just-stored 32-byte copy misses store forwarding.
    let rb = RayBoxes::new(ray);
    if SIMD && !rb.by_bits {
        // Rays along an axis or reaching behind their origin (rare) take the portable
        // kernels, which answer as the SIMD ones do: the SIMD box tests are then compiled
        // for integer order alone, with no branch in the loop.
        return closest_portable::<P, W, N, COUNT>(bvh, prims, ray, c);
    }
    if COUNT {
        c.rays += 1;
    }
    if bvh.root == EMPTY {
        return None;
    }
    let mut w = Work::default();
    let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = bvh.root;
    // Interior nodes down to the first leaf, without the block test's constants (two
    // divisions and their spills): most camera rays miss the mesh and never need them.
    while !is_leaf(cur) {
        if COUNT {
            w.nodes += 1;
        }
        match enter_closest::<W, N, SIMD, PF>(bvh, cur, &rb, ray.t_max, &mut stack, &mut sp).or_else(|| pop_closest(&stack, &mut sp, ray.t_max)) {
            Some(next) => cur = next,
            None => {
                if COUNT {
                    c.nodes_visited += w.nodes;
                }
                return None;
            }
        }
    }
    let s = ShearedRay::new(ray);
    let br = BlockRay::new(&s);
    let mut ray = *ray;
    let mut best = None;
    loop {
        if COUNT {
            w.nodes += 1;
        }
        if is_leaf(cur) {
            leaf_closest::<P, SIMD, COUNT>(leaf_slice(bvh, cur), prims, &s, &br, &mut ray, &mut best, &mut w);
        } else if let Some(next) = enter_closest::<W, N, SIMD, PF>(bvh, cur, &rb, ray.t_max, &mut stack, &mut sp) {
            cur = next;
            continue;
        }
        match pop_closest(&stack, &mut sp, ray.t_max) {
            Some(next) => cur = next,
            None => break,
        }
    }
    if COUNT {
        c.nodes_visited += w.nodes;
        c.prim_tests += w.tests;
    }
    best
}

#[inline(always)]
pub(super) fn any<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const SIMD: bool, const COUNT: bool, const PF: bool>(bvh: &WideBvh<W, N>, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
    let rb = RayBoxes::new(ray);
    if SIMD && !rb.by_bits {
        // As in `closest`.
        return any_portable::<P, W, N, COUNT>(bvh, prims, ray, c);
    }
    if COUNT {
        c.rays += 1;
    }
    if bvh.root == EMPTY {
        return false;
    }
    let s = ShearedRay::new(ray);
    let br = BlockRay::new(&s);
    let mut w = Work::default();
    let mut stack = [const { MaybeUninit::<ChildRef>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = bvh.root;
    let mut hit = false;
    'walk: loop {
        if COUNT {
            w.nodes += 1;
        }
        if is_leaf(cur) {
            if leaf_any::<P, SIMD, COUNT>(leaf_slice(bvh, cur), prims, &s, &br, ray, &mut w) {
                hit = true;
                break;
            }
        } else {
            let node = bvh.node(cur);
            let mut tnear = [0.0f32; W];
            let mut mask = node.boxes::<SIMD>(&rb, ray.t_max * ROBUST_FAR, &mut tnear);
            if mask != 0 {
                // Any hit will do: no ordering, the first lane is entered, the rest pushed.
                cur = entered::<W, N, PF>(bvh, node.child(mask.trailing_zeros() as usize));
                mask &= mask - 1;
                while mask != 0 {
                    let child = node.child(mask.trailing_zeros() as usize);
                    if PF {
                        prefetch(bvh, child);
                    }
                    stack[sp] = MaybeUninit::new(child);
                    sp += 1;
                    mask &= mask - 1;
                }
                continue 'walk;
            }
        }
        if sp == 0 {
            break;
        }
        sp -= 1;
        // SAFETY: entries below `sp` were written by the pushes above.
        cur = unsafe { stack[sp].assume_init() };
    }
    if COUNT {
        c.nodes_visited += w.nodes;
        c.prim_tests += w.tests;
    }
    hit
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    /// The entries the insertion sort of `enter_closest` pushes for `mask` (far to near)
    /// and the child it enters.
    fn by_insertion(tnear: &[f32; 8], mask: u32, child: &[ChildRef; 8]) -> (Vec<(ChildRef, u32)>, ChildRef) {
        let (mut keys, mut n, mut m) = ([0u32; 8], 0, mask);
        while m != 0 {
            let l = m.trailing_zeros();
            m &= m - 1;
            insert_sorted(&mut keys, &mut n, (tnear[l as usize].to_bits() & !7) | l);
        }
        let lane = |k: u32| (k & 7) as usize;
        (keys[1..n].iter().rev().map(|&k| (child[lane(k)], tnear[lane(k)].to_bits())).collect(), child[lane(keys[0])])
    }

    /// Every mask of three to eight entered children, with distinct distances, ties (the
    /// lane decides) and distances that differ only in the three low bits the key drops.
    #[test]
    fn the_avx2_push_sorts_as_the_insertion_sort_does() {
        if !is_x86_feature_detected!("avx2") {
            return;
        }
        let child: [ChildRef; 8] = std::array::from_fn(|l| 100 + 7 * l as u32);
        let mut seed = 1u32;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed
        };
        for mask in (0u32..256).filter(|m| m.count_ones() >= 3) {
            for round in 0..40 {
                let tnear: [f32; 8] = std::array::from_fn(|_| match round % 4 {
                    0 => (next() % 1000) as f32 * 0.37,
                    1 => (next() % 3) as f32,
                    2 => f32::from_bits(0x4000_0000 | (next() & 0xF)),
                    _ => f32::from_bits(next() & 0x7F7F_FFFF),
                });
                let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
                let mut sp = 3;
                // SAFETY: AVX2 was detected.
                let (nearest, pushed) = unsafe { push_sorted_avx2(&tnear, mask, child, &mut stack, &mut sp) };
                let got: Vec<_> = stack[3..sp].iter().map(|e| unsafe { e.assume_init() }).map(|e| (e.node, e.t.to_bits())).collect();
                let (want, want_nearest) = by_insertion(&tnear, mask, &child);
                assert_eq!((got, nearest, pushed), (want.clone(), want_nearest, want.len()), "mask {mask:#010b}, distances {tnear:?}");
            }
        }
    }
}
