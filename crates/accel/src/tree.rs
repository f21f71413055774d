//! What the binary trees of bounding volumes share (the BVH's boxes, the bottom-up
//! hierarchy's spheres): nodes stored with siblings adjacent and the root at 0, walked front
//! to back, measured (depth, leaves, SAH cost) and validated by the same code. Each tree
//! brings only its volume: how a ray enters it and what "inside" means.

use raylab_core::{Ray, Vec3};

use crate::leaf::{any_hit, Closest};
use crate::{AccelStats, Counters, Hit, Primitives, ValidationError};

/// Trees deeper than this are cut into leaves by every builder: bounds the traversal stack.
pub(crate) const MAX_DEPTH: usize = 64;

/// A node of a binary tree stored with siblings adjacent and the root at 0: what the walk,
/// the statistics and the validation need of it.
pub(crate) trait TreeNode {
    fn is_leaf(&self) -> bool;
    /// First child (interior) or first index (leaf).
    fn left_first(&self) -> usize;
    fn count(&self) -> usize;
    /// Entry distance of the ray into the node's volume, if it enters within its interval.
    fn entry(&self, ray: &Ray, inv_dir: Vec3) -> Option<f32>;
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

/// What a tree's volumes must satisfy, for [`validate_tree`].
pub(crate) struct Containment<C, L> {
    /// `child` lies inside `parent` (up to the volume's rounding).
    pub child_inside: C,
    /// Leaf `i` may hold primitive `p`; otherwise the error message.
    pub leaf_holds: L,
    /// Every primitive in exactly one leaf (else at least one: spatial splits duplicate).
    pub each_once: bool,
}

/// Checks a tree built for `built_for` primitives against `prims`: every node reached once
/// from the root (children stored after their parent, in range), leaves pointing into
/// `indices` at existing primitives, volumes nested as `rules` says, and every primitive in
/// a leaf. The first problem found is the error, named after `name`.
pub(crate) fn validate_tree<N: TreeNode, P: Primitives + ?Sized>(
    name: &'static str,
    nodes: &[N],
    indices: &[u32],
    built_for: usize,
    prims: &P,
    rules: Containment<impl Fn(&N, &N) -> bool, impl Fn(usize, &N, u32) -> Result<(), String>>,
) -> Result<(), ValidationError> {
    let err = |m: String| Err(ValidationError::new(name, m));
    if prims.len() != built_for {
        return err(format!("built for {built_for} primitives, given {}", prims.len()));
    }
    if nodes.is_empty() {
        return if prims.is_empty() { Ok(()) } else { err("no nodes for a non-empty scene".into()) };
    }
    let mut seen = vec![0u32; prims.len()];
    let mut reached = vec![false; nodes.len()];
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        if std::mem::replace(&mut reached[i], true) {
            return err(format!("node {i} reached twice"));
        }
        let n = &nodes[i];
        let first = n.left_first();
        if n.is_leaf() {
            let Some(leaf) = indices.get(first..first + n.count()) else {
                return err(format!("leaf {i} points past the index array"));
            };
            for &p in leaf {
                if p as usize >= prims.len() {
                    return err(format!("leaf {i} holds primitive {p} of {}", prims.len()));
                }
                seen[p as usize] += 1;
                (rules.leaf_holds)(i, n, p).or_else(err)?;
            }
        } else {
            if first + 1 >= nodes.len() || first <= i {
                return err(format!("node {i} has children {first}, {} out of order or range", first + 1));
            }
            for c in [first, first + 1] {
                if !(rules.child_inside)(n, &nodes[c]) {
                    return err(format!("child {c} sticks out of node {i}"));
                }
                stack.push(c);
            }
        }
    }
    if let Some(i) = reached.iter().position(|r| !r) {
        return err(format!("node {i} is unreachable"));
    }
    if let Some(p) = seen.iter().position(|&c| c == 0) {
        return err(format!("primitive {p} is in no leaf"));
    }
    match seen.iter().position(|&c| c > 1) {
        Some(p) if rules.each_once => err(format!("primitive {p} is in {} leaves, not one", seen[p])),
        _ => Ok(()),
    }
}
