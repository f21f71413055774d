//! PLOC, Parallel Locally-Ordered Clustering (Meister & Bittner 2018, "Parallel Locally-
//! Ordered Clustering for Bounding Volume Hierarchy Construction"): agglomerative
//! clustering (Walter et al. 2008) made parallel by searching each cluster's nearest
//! neighbour only within `radius` positions along the Morton curve. Mutual nearest
//! neighbours merge; the rest wait for the next round.
//!
//! The clustering works on any [`Volume`]: `lbvh-ploc` merges boxes, `sphere-bvh` spheres.

use rayon::prelude::*;
use raylab_core::{Aabb, Vec3};

use super::lbvh::{self, Tree, TreeNode, Volume};
use super::morton::morton_order;
use super::Bvh;
use crate::{BuildOptions, Primitives};

/// Clusters `leaves` (one volume per primitive; `centers` orders them along the Morton
/// curve) into one tree. The distance of two clusters is the area of their union.
///
/// Ties are broken by the pair's gap along the curve, then towards pairs whose lower end sits
/// at an even position, then by position, so the pair order is total and the globally
/// closest pair is always mutual: every round merges at least one pair and the loop ends.
/// The parity makes a run of equal volumes (duplicated geometry) pair up (0, 1), (2, 3), ...
/// in one round; ordered by position alone, every cluster of the run chose the lowest pair,
/// so one cluster grew by a primitive per round: n rounds, and a chain cut at depth 64 into
/// a leaf of n − 63 (4000 identical triangles took 5 s to build).
pub(crate) fn cluster<V: Volume>(leaves: &[V], centers: &[Vec3], radius: usize) -> Tree<V> {
    let (order, _) = morton_order(centers);
    let n = leaves.len();
    let mut nodes: Vec<TreeNode> = Vec::with_capacity(2 * n);
    let mut volumes: Vec<V> = Vec::with_capacity(2 * n);
    for &p in &order {
        nodes.push(TreeNode::Leaf { prim: p });
        volumes.push(leaves[p as usize]);
    }
    // Active clusters in Morton order: node ids and their volumes.
    let mut active: Vec<u32> = (0..n as u32).collect();
    let mut vols: Vec<V> = volumes.clone();
    let radius = radius.max(1);
    while active.len() > 1 {
        let c = active.len();
        let vols_ref = &vols;
        // The union is always formed lower position first, so that d(i, j) == d(j, i)
        // bit for bit (the sphere union is not symmetric in rounding).
        let dist = |i: usize, j: usize| {
            let (a, b) = (i.min(j), i.max(j));
            vols_ref[a].union(vols_ref[b]).area()
        };
        let nearest: Vec<usize> = (0..c)
            .into_par_iter()
            .map(|i| {
                let (lo, hi) = (i.saturating_sub(radius), (i + radius).min(c - 1));
                // (distance, gap along the curve, parity of the lower end, lower end)
                let mut best = (f32::INFINITY, usize::MAX, usize::MAX, usize::MAX);
                for j in (lo..=hi).filter(|&j| j != i) {
                    let key = (dist(i, j), i.abs_diff(j), i.min(j) % 2, i.min(j));
                    if key.0.total_cmp(&best.0).then((key.1, key.2, key.3).cmp(&(best.1, best.2, best.3))).is_lt() {
                        best = key;
                    }
                }
                if best.3 == i { best.3 + best.1 } else { best.3 }
            })
            .collect();
        (active, vols) = merge_round(&active, &vols, &nearest, &mut nodes, &mut volumes, MERGE_CHUNK);
    }
    let root = active.first().copied().unwrap_or(0);
    Tree { nodes, volumes, root }
}

/// Positions handled by one task of a merge round.
const MERGE_CHUNK: usize = 4096;

/// One round's merges: every cluster `i` whose nearest neighbour `j` has `i` as its own
/// nearest merges with it, the pair's new interior node taking `i`'s position when `i < j`
/// and `j`'s position going; the other clusters stay. New nodes are appended in position
/// order. Chunks of positions run in parallel, each writing its own ranges of the new
/// nodes and of the next round's clusters (placed by prefix sums of the chunks' counts).
fn merge_round<V: Volume>(active: &[u32], vols: &[V], nearest: &[usize], nodes: &mut Vec<TreeNode>, volumes: &mut Vec<V>, chunk: usize) -> (Vec<u32>, Vec<V>) {
    let mutual = |i: usize| nearest[nearest[i]] == i;
    let counts: Vec<(usize, usize)> = (0..active.len())
        .into_par_iter()
        .chunks(chunk)
        .map(|chunk| {
            let merges = chunk.iter().filter(|&&i| mutual(i) && i < nearest[i]).count();
            let gone = chunk.iter().filter(|&&i| mutual(i) && i > nearest[i]).count();
            (merges, chunk.len() - gone)
        })
        .collect();
    let (merges, stay): (usize, usize) = counts.iter().fold((0, 0), |(m, s), &(cm, cs)| (m + cm, s + cs));
    let first_new = nodes.len() as u32;
    nodes.resize(nodes.len() + merges, TreeNode::Leaf { prim: 0 });
    let mut next_active = vec![0u32; stay];
    let mut next_vols = vec![vols[0]; stay];
    // Each chunk's part of the new nodes and of the next round's clusters.
    let mut parts = Vec::with_capacity(counts.len());
    let (mut new_nodes, mut new_vols) = (&mut nodes[first_new as usize..], Vec::with_capacity(merges));
    new_vols.resize(merges, vols[0]);
    let (mut new_vols_rest, mut act_rest, mut vol_rest) = (&mut new_vols[..], &mut next_active[..], &mut next_vols[..]);
    let mut node_base = first_new;
    for (k, &(cm, cs)) in counts.iter().enumerate() {
        let (nn, nr) = std::mem::take(&mut new_nodes).split_at_mut(cm);
        let (nv, nvr) = std::mem::take(&mut new_vols_rest).split_at_mut(cm);
        let (a, ar) = std::mem::take(&mut act_rest).split_at_mut(cs);
        let (v, vr) = std::mem::take(&mut vol_rest).split_at_mut(cs);
        parts.push((k * chunk, node_base, nn, nv, a, v));
        (new_nodes, new_vols_rest, act_rest, vol_rest) = (nr, nvr, ar, vr);
        node_base += cm as u32;
    }
    parts.into_par_iter().for_each(|(start, node_base, nn, nv, a, v)| {
        let (mut m, mut s) = (0, 0);
        for i in start..(start + chunk).min(active.len()) {
            let j = nearest[i];
            if mutual(i) && i > j {
                continue;
            }
            if mutual(i) {
                let u = vols[i].union(vols[j]);
                nn[m] = TreeNode::Interior { children: [active[i], active[j]] };
                nv[m] = u;
                (a[s], v[s]) = (node_base + m as u32, u);
                m += 1;
            } else {
                (a[s], v[s]) = (active[i], vols[i]);
            }
            s += 1;
        }
    });
    volumes.extend_from_slice(&new_vols);
    (next_active, next_vols)
}

/// Builds a BVH by PLOC over the primitives' boxes, then collapses small subtrees by SAH.
pub fn build<P: Primitives + ?Sized>(prims: &P, opts: &BuildOptions) -> Bvh {
    let n = prims.len();
    let bounds = lbvh::grown_bounds(prims);
    let centroids: Vec<Vec3> = bounds.par_iter().map(Aabb::centroid).collect();
    let tree = cluster(&bounds, &centroids, opts.ploc_radius);
    lbvh::from_tree(tree, n, "lbvh-ploc", opts)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A round in chunks of 3 makes the merges a plain sweep makes: pairs of mutual
    /// neighbours become new nodes in position order, at the lower one's position.
    #[test]
    fn chunked_merge_round_is_the_serial_sweep() {
        let mut rng = raylab_core::Pcg32::new(7, 0);
        for _ in 0..200 {
            let c = 2 + rng.below(40) as usize;
            let nearest: Vec<usize> = (0..c)
                .map(|i| {
                    let j = rng.below(c as u32 - 1) as usize;
                    if j >= i { j + 1 } else { j }
                })
                .collect();
            let active: Vec<u32> = (0..c as u32).map(|i| 100 + i).collect();
            let vols: Vec<Aabb> = (0..c).map(|i| Aabb::new(Vec3::splat(i as f32), Vec3::splat(i as f32 + 1.5))).collect();
            // The serial sweep.
            let (mut want_nodes, mut want_vols) = (Vec::new(), Vec::new());
            let (mut want_active, mut want_next) = (Vec::new(), Vec::new());
            let mut merged = vec![false; c];
            for i in 0..c {
                let j = nearest[i];
                if merged[i] {
                    continue;
                }
                if nearest[j] == i && i < j {
                    let v = vols[i].union(vols[j]);
                    want_nodes.push((active[i], active[j]));
                    want_vols.push(v);
                    merged[j] = true;
                    want_active.push(1000 + want_nodes.len() as u32 - 1);
                    want_next.push(v);
                } else {
                    want_active.push(active[i]);
                    want_next.push(vols[i]);
                }
            }
            let (mut nodes, mut volumes) = (vec![TreeNode::Leaf { prim: 0 }; 1000], vec![Aabb::EMPTY; 1000]);
            let (next_active, next_vols) = merge_round(&active, &vols, &nearest, &mut nodes, &mut volumes, 3);
            assert_eq!(next_active, want_active, "nearest {nearest:?}");
            assert_eq!(next_vols, want_next);
            assert_eq!(volumes[1000..], want_vols[..]);
            let got: Vec<(u32, u32)> = nodes[1000..].iter().map(|n| match *n {
                TreeNode::Interior { children: [a, b] } => (a, b),
                TreeNode::Leaf { .. } => panic!("a leaf among the new nodes"),
            }).collect();
            assert_eq!(got, want_nodes);
        }
    }
}
