//! Front-to-back traversal of binary trees of bounding volumes (boxes here, spheres in
//! `sphere_bvh.rs`): both children are tested and the nearer one entered first, so that the
//! closest hit shrinks `t_max` early.

use raylab_core::{Ray, Vec3};

use super::{Bvh, BvhNode, MAX_DEPTH};
use crate::leaf::{any_hit, Closest};
use crate::wide::kernels::ROBUST_FAR;
use crate::{Accel, AccelStats, Counters, Hit, Primitives, ValidationError};

impl Accel for Bvh {
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        closest_in_tree(&self.nodes, &self.indices, prims, ray, c)
    }

    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        any_in_tree(&self.nodes, &self.indices, prims, ray, c)
    }

    fn stats(&self) -> AccelStats {
        Bvh::stats(self)
    }

    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        Bvh::validate(self, prims)
    }
}

/// Closest hit in a tree whose leaves point into `indices`.
#[inline]
pub(crate) fn closest_in_tree<N: TreeNode, P: Primitives + ?Sized>(nodes: &[N], indices: &[u32], prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
    c.rays += 1;
    let mut ray = *ray;
    let mut closest = Closest::new(prims);
    walk_tree(nodes, &mut ray, c, |ray, first, count, c| closest.test(ray, indices[first..first + count].iter().copied(), c));
    closest.best
}

/// Any hit in a tree whose leaves point into `indices`; stops at the first.
#[inline]
pub(crate) fn any_in_tree<N: TreeNode, P: Primitives + ?Sized>(nodes: &[N], indices: &[u32], prims: &P, ray: &Ray, c: &mut Counters) -> bool {
    c.rays += 1;
    let mut ray = *ray;
    let mut hit = false;
    walk_tree(nodes, &mut ray, c, |ray, first, count, c| {
        hit = any_hit(prims, ray, indices[first..first + count].iter().copied(), c);
        hit
    });
    hit
}

/// A node of a binary tree stored with siblings adjacent and the root at 0 (BVHs of boxes
/// or of spheres): what [`walk_tree`] needs of it.
pub(crate) trait TreeNode {
    fn is_leaf(&self) -> bool;
    /// First child (interior) or first index (leaf).
    fn left_first(&self) -> usize;
    fn count(&self) -> usize;
    /// Entry distance of the ray into the node's volume, if it enters within its interval.
    fn entry(&self, ray: &Ray, inv_dir: Vec3) -> Option<f32>;
}

impl TreeNode for BvhNode {
    #[inline]
    fn is_leaf(&self) -> bool {
        self.count > 0
    }
    #[inline]
    fn left_first(&self) -> usize {
        self.left_first as usize
    }
    #[inline]
    fn count(&self) -> usize {
        self.count as usize
    }
    /// Against `t_max` widened by `1 + 2γ₃`, as the wide traversal does: the triangles
    /// around a vertex hit at distances an ulp apart, and the box of the nearer one may
    /// round its entry above the farther hit; pruning it returned a hit an ulp behind the
    /// oracle's (issue 12).
    #[inline]
    fn entry(&self, ray: &Ray, inv_dir: Vec3) -> Option<f32> {
        self.bounds().intersect(ray.origin, inv_dir, ray.t_min, ray.t_max * ROBUST_FAR).map(|(t, _)| t)
    }
}

/// Front-to-back traversal with an explicit stack: both children's volumes are tested and
/// the nearer one is entered first, so that the closest hit shrinks `t_max` early.
#[inline]
pub(crate) fn walk_tree<N: TreeNode>(nodes: &[N], ray: &mut Ray, c: &mut Counters, mut leaf: impl FnMut(&mut Ray, usize, usize, &mut Counters) -> bool) {
    let Some(root) = nodes.first() else { return };
    let inv = ray.inv_dir();
    if root.entry(ray, inv).is_none() {
        return;
    }
    let mut stack = [0u32; MAX_DEPTH + 1];
    let mut sp = 0usize;
    let mut node = 0usize;
    loop {
        c.nodes_visited += 1;
        let n = &nodes[node];
        if n.is_leaf() {
            if leaf(ray, n.left_first(), n.count(), c) {
                return;
            }
        } else {
            let l = n.left_first();
            match (nodes[l].entry(ray, inv), nodes[l + 1].entry(ray, inv)) {
                (Some(tl), Some(tr)) => {
                    let (near, far) = if tl <= tr { (l, l + 1) } else { (l + 1, l) };
                    stack[sp] = far as u32;
                    sp += 1;
                    node = near;
                    continue;
                }
                (Some(_), None) => {
                    node = l;
                    continue;
                }
                (None, Some(_)) => {
                    node = l + 1;
                    continue;
                }
                (None, None) => {}
            }
        }
        // Pop until a node that may still hold something nearer than the current hit.
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            node = stack[sp] as usize;
            if nodes[node].entry(ray, inv).is_some() {
                break;
            }
        }
    }
}

/// Shape statistics of a tree (depth, leaves, interior nodes) and its SAH cost, with node
/// areas from `area` taken relative to the root's.
pub(crate) fn tree_stats<N: TreeNode>(nodes: &[N], s: &mut AccelStats, area: impl Fn(&N) -> f64) {
    let Some(root) = nodes.first() else { return };
    let root_area = area(root).max(f64::MIN_POSITIVE);
    let mut stack = vec![(0usize, 1usize)];
    let mut cost = 0.0f64;
    while let Some((i, depth)) = stack.pop() {
        let n = &nodes[i];
        let rel = area(n) / root_area;
        s.max_depth = s.max_depth.max(depth);
        if n.is_leaf() {
            s.add_leaf(n.count());
            cost += rel * n.count() as f64;
        } else {
            s.interior_nodes += 1;
            cost += rel;
            stack.push((n.left_first(), depth + 1));
            stack.push((n.left_first() + 1, depth + 1));
        }
    }
    s.sah_cost = cost;
}
