//! SAH kd-tree: space cut by axis-aligned planes into voxels, built in O(N log N) by the
//! event sweep of Wald & Havran 2006, "On building fast kd-trees for ray tracing, and on
//! doing that in O(N log N)", with perfect splits (primitive bounds clipped to each voxel),
//! stored as pbrt's 8-byte nodes and traversed front to back over the ray's `t` interval
//! (pbrt-v3's `KdTreeAccel`).

mod build;
mod traverse;

use raylab_core::Aabb;

use crate::{AccelStats, BuildOptions, Primitives, ValidationError};

/// One kd-tree node, 8 bytes (pbrt's `KdAccelNode`).
///
/// `flags & 3` is the split axis (0-2) of an interior node or 3 for a leaf. Interior: `data`
/// holds the split position's bits, the child below the plane is the next node and the
/// child above is `flags >> 2`. Leaf: `indices[data .. data + (flags >> 2)]`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct KdNode {
    data: u32,  // 4 bytes: split position (f32 bits) or first index
    flags: u32, // 4 -> 8: axis or leaf tag in 2 bits, above child or count in 30
}

const _: () = assert!(std::mem::size_of::<KdNode>() == 8);

const LEAF: u32 = 3;

impl KdNode {
    fn interior(axis: usize, split: f32, above: u32) -> Self {
        Self { data: split.to_bits(), flags: axis as u32 | (above << 2) }
    }

    fn leaf(first: u32, count: u32) -> Self {
        Self { data: first, flags: LEAF | (count << 2) }
    }

    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.flags & 3 == LEAF
    }

    #[inline]
    pub fn axis(&self) -> usize {
        (self.flags & 3) as usize
    }

    #[inline]
    pub fn split(&self) -> f32 {
        f32::from_bits(self.data)
    }

    /// Index of the child above the plane (the child below is the next node).
    #[inline]
    pub fn above(&self) -> usize {
        (self.flags >> 2) as usize
    }

    #[inline]
    pub fn first(&self) -> usize {
        self.data as usize
    }

    #[inline]
    pub fn count(&self) -> usize {
        (self.flags >> 2) as usize
    }
}

/// A built kd-tree.
///
/// Invariants: nodes are in depth-first order (root at 0, below child next); every split
/// lies inside its voxel; a leaf lists only primitives whose bounds touch its voxel, and
/// every primitive is listed by at least one leaf (by several when it straddles planes).
#[derive(Debug)]
pub struct KdTree {
    nodes: Vec<KdNode>,
    indices: Vec<u32>,
    /// The root voxel: the scene bounds grown by `margin`.
    bounds: Aabb,
    /// Position tolerance of the traversal's plane decisions ([`crate::robust_margin`]).
    margin: f32,
    primitives: usize,
    pub(crate) build_ms: f64,
}

/// Children of the voxel `v` split at `pos` on `axis`: (below, above).
fn split_voxel(v: &Aabb, axis: usize, pos: f32) -> (Aabb, Aabb) {
    let (mut below, mut above) = (*v, *v);
    below.max[axis] = pos;
    above.min[axis] = pos;
    (below, above)
}

impl KdTree {
    pub fn build<P: Primitives + ?Sized>(prims: &P, opts: &BuildOptions) -> Self {
        build::build(prims, opts)
    }

    /// Visits every node with its voxel and depth (root depth 1), depth first.
    fn visit(&self, mut f: impl FnMut(usize, &Aabb, usize)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![(0usize, self.bounds, 1usize)];
        while let Some((i, v, depth)) = stack.pop() {
            f(i, &v, depth);
            let n = &self.nodes[i];
            if !n.is_leaf() && n.above() < self.nodes.len() {
                let (below, above) = split_voxel(&v, n.axis(), n.split());
                stack.push((n.above(), above, depth + 1));
                stack.push((i + 1, below, depth + 1));
            }
        }
    }

    pub fn stats(&self) -> AccelStats {
        let mut s = AccelStats {
            name: "kdtree".into(),
            build_ms: self.build_ms,
            primitives: self.primitives,
            memory_bytes: self.nodes.len() * std::mem::size_of::<KdNode>() + self.indices.len() * 4,
            ..Default::default()
        };
        let root_area = self.bounds.half_area().max(f32::MIN_POSITIVE) as f64;
        let (mut cost, mut empty) = (0.0f64, 0usize);
        self.visit(|i, v, depth| {
            let n = &self.nodes[i];
            let rel = v.half_area() as f64 / root_area;
            s.max_depth = s.max_depth.max(depth);
            if n.is_leaf() {
                s.add_leaf(n.count());
                empty += usize::from(n.count() == 0);
                cost += rel * n.count() as f64;
            } else {
                s.interior_nodes += 1;
                cost += rel;
            }
        });
        s.sah_cost = cost;
        s.note("empty leaves", empty);
        s
    }

    pub fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        let err = |m: String| Err(ValidationError::new("kdtree", m));
        if prims.len() != self.primitives {
            return err(format!("built for {} primitives, given {}", self.primitives, prims.len()));
        }
        if self.nodes.is_empty() {
            return if prims.is_empty() { Ok(()) } else { err("no nodes for a non-empty scene".into()) };
        }
        let mut problem = None;
        let mut reached = vec![false; self.nodes.len()];
        let mut seen = vec![false; prims.len()];
        let mut referenced = 0usize;
        self.visit(|i, v, _| {
            if problem.is_some() {
                return;
            }
            if std::mem::replace(&mut reached[i], true) {
                problem = Some(format!("node {i} reached twice"));
                return;
            }
            let n = &self.nodes[i];
            if n.is_leaf() {
                let (first, count) = (n.first(), n.count());
                referenced += count;
                let Some(leaf) = self.indices.get(first..first + count) else {
                    problem = Some(format!("leaf {i} points past the index array"));
                    return;
                };
                for &p in leaf {
                    if p as usize >= prims.len() {
                        problem = Some(format!("leaf {i} holds primitive {p} of {}", prims.len()));
                    } else if prims.bounds(p).intersection(*v).is_empty() {
                        problem = Some(format!("primitive {p} does not touch the voxel of leaf {i}"));
                    } else {
                        seen[p as usize] = true;
                    }
                }
            } else {
                let (a, p) = (n.axis(), n.split());
                if n.above() <= i + 1 || n.above() >= self.nodes.len() {
                    problem = Some(format!("node {i} has its above child at {}", n.above()));
                } else if !(p >= v.min[a] && p <= v.max[a]) {
                    problem = Some(format!("split {p} of node {i} lies outside its voxel on axis {a}"));
                }
            }
        });
        if let Some(m) = problem {
            return err(m);
        }
        if referenced != self.indices.len() {
            return err(format!("leaves reference {referenced} of {} indices", self.indices.len()));
        }
        if let Some(i) = reached.iter().position(|r| !r) {
            return err(format!("node {i} is unreachable"));
        }
        match seen.iter().position(|s| !s) {
            Some(p) => err(format!("primitive {p} is in no leaf")),
            None => Ok(()),
        }
    }
}
