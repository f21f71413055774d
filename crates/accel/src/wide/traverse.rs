//! Closest-hit and any-hit traversal of a wide BVH, generic over the width, the kernel
//! (SIMD or portable) and whether work is counted (a const flag, so the fast path carries
//! no counter code).
//!
//! The stack holds `(node, entry distance)` pairs and is never cleared: a pop whose entry
//! lies beyond the current closest hit is dropped without touching the node's memory.
//! Children are pushed far to near by their entry distance (the key's low bits hold the
//! lane, Embree's trick), so the nearest is entered first and shrinks `t_max` early.

use std::mem::MaybeUninit;

use raylab_core::intersect::ShearedRay;
use raylab_core::Ray;

use super::kernels::{boxes_portable, triangle_candidates, RayBoxes, ROBUST_FAR};

/// The triangle filter of the kernel in use (SSE2 on x86-64 for both SIMD widths).
#[inline(always)]
pub(super) fn candidates<const SIMD: bool>(b: &TriBlock, s: &ShearedRay) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if SIMD {
        return super::kernels::triangle_candidates_sse(b, s);
    }
    triangle_candidates(b, s)
}
use super::node::{is_leaf, leaf_blocks, ChildRef, TriBlock, WideNode, EMPTY};
use super::WideBvh;
use crate::{Counters, Hit, PrimHit, Primitives};

/// Stack entries: at most `W - 1` pushes per level and trees at most `MAX_DEPTH + 1`
/// wide levels deep (a wide level consumes at least one binary level; a split leaf adds
/// one), so `65 · 7 = 455` entries suffice for `W = 8`.
pub(super) const STACK: usize = 512;

#[derive(Clone, Copy)]
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

#[inline(always)]
pub(super) fn child_boxes<const W: usize, const SIMD: bool>(node: &WideNode<W>, r: &RayBoxes, t_max: f32, tnear: &mut [f32; W]) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if SIMD {
        if W == 8 {
            // SAFETY: `W == 8`, so these are the same types; SIMD = true with W = 8 is only
            // instantiated inside `#[target_feature(enable = "avx2")]` functions that the
            // build selects after `is_x86_feature_detected!("avx2")`.
            return unsafe { super::kernels::boxes_avx2(&*(node as *const WideNode<W>).cast::<WideNode<8>>(), r, t_max, &mut *(tnear as *mut [f32; W]).cast::<[f32; 8]>()) };
        }
        if W == 4 {
            // SAFETY: `W == 4`: the same types.
            return unsafe { super::kernels::boxes_sse(&*(node as *const WideNode<W>).cast::<WideNode<4>>(), r, t_max, &mut *(tnear as *mut [f32; W]).cast::<[f32; 4]>()) };
        }
    }
    boxes_portable(node, r, t_max, tnear)
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

/// Closest hit among the blocks of a leaf; moves `ray.t_max` to each hit found.
#[inline(always)]
fn leaf_closest<P: Primitives + ?Sized, const SIMD: bool, const COUNT: bool>(blocks: &[TriBlock], prims: &P, s: &ShearedRay, ray: &mut Ray, best: &mut Option<Hit>, w: &mut Work) {
    for b in blocks {
        let mut m = candidates::<SIMD>(b, s);
        if COUNT {
            w.tests += b.prim.iter().filter(|&&p| p != EMPTY).count() as u64;
        }
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let p = b.prim[l];
            let hit = if p & TriBlock::OTHER != 0 {
                prims.intersect(p & !TriBlock::OTHER, ray)
            } else {
                s.triangle(ray.t_min, ray.t_max, b.vertex(l, 0), b.vertex(l, 1), b.vertex(l, 2)).map(|(t, u, v)| PrimHit { t, u, v })
            };
            if let Some(h) = hit {
                let prim = p & !TriBlock::OTHER;
                if wins(h.t, prim, best) {
                    ray.t_max = h.t;
                    *best = Some(Hit::new(prim, h));
                }
            }
        }
    }
}

/// Whether anything in the blocks of a leaf is hit; stops at the first.
#[inline(always)]
fn leaf_any<P: Primitives + ?Sized, const SIMD: bool, const COUNT: bool>(blocks: &[TriBlock], prims: &P, s: &ShearedRay, ray: &Ray, w: &mut Work) -> bool {
    for b in blocks {
        let mut m = candidates::<SIMD>(b, s);
        if COUNT {
            w.tests += b.prim.iter().filter(|&&p| p != EMPTY).count() as u64;
        }
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let p = b.prim[l];
            let hit = if p & TriBlock::OTHER != 0 {
                prims.intersect(p & !TriBlock::OTHER, ray).is_some()
            } else {
                s.triangle(ray.t_min, ray.t_max, b.vertex(l, 0), b.vertex(l, 1), b.vertex(l, 2)).is_some()
            };
            if hit {
                return true;
            }
        }
    }
    false
}

#[inline(always)]
pub(super) fn leaf_slice<const W: usize>(bvh: &WideBvh<W>, r: ChildRef) -> &[TriBlock] {
    let (first, n) = leaf_blocks(r);
    &bvh.blocks[first..first + n]
}

#[inline(always)]
pub(super) fn closest<P: Primitives + ?Sized, const W: usize, const SIMD: bool, const COUNT: bool>(bvh: &WideBvh<W>, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
    if COUNT {
        c.rays += 1;
    }
    if bvh.root == EMPTY {
        return None;
    }
    let mut ray = *ray;
    let rb = RayBoxes::new(&ray);
    let s = ShearedRay::new(&ray);
    let mut best = None;
    let mut w = Work::default();
    let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = bvh.root;
    'walk: loop {
        if COUNT {
            w.nodes += 1;
        }
        if is_leaf(cur) {
            leaf_closest::<P, SIMD, COUNT>(leaf_slice(bvh, cur), prims, &s, &mut ray, &mut best, &mut w);
        } else {
            let node = &bvh.nodes[cur as usize];
            let mut tnear = [0.0f32; W];
            let mask = child_boxes::<W, SIMD>(node, &rb, ray.t_max * ROBUST_FAR, &mut tnear);
            if mask != 0 {
                let first = mask.trailing_zeros() as usize;
                if mask & (mask - 1) == 0 {
                    cur = node.child[first];
                    continue 'walk;
                }
                // Sort the hit lanes by entry distance: keys are the distance's bits (in
                // order for t >= 0) with the lane in the low bits.
                let lane_bits = W as u32 - 1;
                let mut keys = [0u32; W];
                let mut n = 0;
                let mut m = mask;
                while m != 0 {
                    let l = m.trailing_zeros();
                    m &= m - 1;
                    let key = (tnear[l as usize].to_bits() & !lane_bits) | l;
                    let mut k = n;
                    while k > 0 && keys[k - 1] > key {
                        keys[k] = keys[k - 1];
                        k -= 1;
                    }
                    keys[k] = key;
                    n += 1;
                }
                for &key in keys[1..n].iter().rev() {
                    let l = (key & lane_bits) as usize;
                    stack[sp] = MaybeUninit::new(Entry { node: node.child[l], t: tnear[l] });
                    sp += 1;
                }
                cur = node.child[(keys[0] & lane_bits) as usize];
                continue 'walk;
            }
        }
        while sp > 0 {
            sp -= 1;
            // SAFETY: entries below `sp` were written by the pushes above.
            let e = unsafe { stack[sp].assume_init() };
            // Widened as in the box test (see `boxes_portable`).
            if e.t <= ray.t_max * ROBUST_FAR {
                cur = e.node;
                continue 'walk;
            }
        }
        break;
    }
    if COUNT {
        c.nodes_visited += w.nodes;
        c.prim_tests += w.tests;
    }
    best
}

#[inline(always)]
pub(super) fn any<P: Primitives + ?Sized, const W: usize, const SIMD: bool, const COUNT: bool>(bvh: &WideBvh<W>, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
    if COUNT {
        c.rays += 1;
    }
    if bvh.root == EMPTY {
        return false;
    }
    let rb = RayBoxes::new(ray);
    let s = ShearedRay::new(ray);
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
            if leaf_any::<P, SIMD, COUNT>(leaf_slice(bvh, cur), prims, &s, ray, &mut w) {
                hit = true;
                break;
            }
        } else {
            let node = &bvh.nodes[cur as usize];
            let mut tnear = [0.0f32; W];
            let mut mask = child_boxes::<W, SIMD>(node, &rb, ray.t_max * ROBUST_FAR, &mut tnear);
            if mask != 0 {
                // Any hit will do: no ordering, the first lane is entered, the rest pushed.
                cur = node.child[mask.trailing_zeros() as usize];
                mask &= mask - 1;
                while mask != 0 {
                    stack[sp] = MaybeUninit::new(node.child[mask.trailing_zeros() as usize]);
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
