//! PLOC, Parallel Locally-Ordered Clustering (Meister & Bittner 2018, "Parallel Locally-
//! Ordered Clustering for Bounding Volume Hierarchy Construction"): agglomerative
//! clustering (Walter et al. 2008) made parallel by searching each cluster's nearest
//! neighbour only within `radius` positions along the Morton curve. Mutual nearest
//! neighbours merge; the rest wait for the next round.
//!
//! The clustering works on any [`Volume`]: `lbvh-ploc` merges boxes, `sphere-bvh` spheres.

use rayon::prelude::*;
use raylab_core::{Aabb, Vec3};

use super::lbvh::{self, morton_order, Tree, TreeNode, Volume};
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
        let mut merged = vec![false; c];
        let mut next_active = Vec::with_capacity(c);
        let mut next_vols = Vec::with_capacity(c);
        for i in 0..c {
            let j = nearest[i];
            if merged[i] {
                continue;
            }
            if nearest[j] == i && i < j {
                let v = vols[i].union(vols[j]);
                nodes.push(TreeNode::Interior { children: [active[i], active[j]] });
                volumes.push(v);
                merged[j] = true;
                next_active.push((nodes.len() - 1) as u32);
                next_vols.push(v);
            } else {
                next_active.push(active[i]);
                next_vols.push(vols[i]);
            }
        }
        active = next_active;
        vols = next_vols;
    }
    let root = active.first().copied().unwrap_or(0);
    Tree { nodes, volumes, root }
}

/// Builds a BVH by PLOC over the primitives' boxes, then collapses small subtrees by SAH.
pub fn build<P: Primitives + ?Sized>(prims: &P, opts: &BuildOptions) -> Bvh {
    let n = prims.len();
    let bounds = lbvh::grown_bounds(prims);
    let centroids: Vec<Vec3> = bounds.par_iter().map(Aabb::centroid).collect();
    let tree = cluster(&bounds, &centroids, opts.ploc_radius);
    lbvh::from_tree(tree, n, "lbvh-ploc", opts)
}
