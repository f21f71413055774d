//! Bounding volume hierarchy: a binary tree of boxes, flattened into an array of 32-byte
//! nodes with siblings adjacent (tinybvh's layout), traversed front to back.
//!
//! Top-down builders (`build.rs`) differ only in where they split: binned SAH (Wald 2007),
//! object median, spatial midpoint. Other builders produce the same nodes: `lbvh.rs`
//! (Morton codes, Karras 2012), `ploc.rs` (Meister & Bittner 2018) and `sbvh.rs` (spatial
//! splits, Stich et al. 2009).

mod build;
pub mod lbvh;
mod node;
pub mod ploc;
mod sah;
pub mod sbvh;
pub(crate) mod traverse;

pub use node::BvhNode;
pub use sah::SahCost;

use raylab_core::Aabb;

use crate::{AccelStats, BuildOptions, Primitives, ValidationError};

/// Where a builder splits a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitMethod {
    /// Binned surface area heuristic (Wald 2007).
    BinnedSah,
    /// Object median along the longest centroid axis.
    Median,
    /// Spatial middle of the centroid bounds along the longest axis.
    Midpoint,
}

impl SplitMethod {
    pub fn accel_name(self) -> &'static str {
        match self {
            SplitMethod::BinnedSah => "bvh",
            SplitMethod::Median => "bvh-median",
            SplitMethod::Midpoint => "bvh-midpoint",
        }
    }
}

/// A built BVH: nodes (root at index 0 when not empty) and the primitive indices the
/// leaves point into.
#[derive(Debug)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    pub indices: Vec<u32>,
    pub name: &'static str,
    pub(crate) build_ms: f64,
    primitives: usize,
    /// Leaves may hold clipped references (SBVH): a primitive may stick out of its leaf's
    /// box, as long as the parts in all its leaves cover it.
    pub(crate) spatial_splits: bool,
}

/// Trees deeper than this are cut into leaves: bounds the traversal stack.
pub(crate) const MAX_DEPTH: usize = 64;

impl Bvh {
    pub fn build<P: Primitives + ?Sized>(prims: &P, method: SplitMethod, opts: &BuildOptions) -> Self {
        let (nodes, indices) = build::build(prims, method, opts);
        Self { nodes, indices, name: method.accel_name(), build_ms: 0.0, primitives: prims.len(), spatial_splits: false }
    }

    /// Wraps nodes made by another builder (LBVH, SBVH, ...) so that they share traversal,
    /// statistics and validation.
    pub fn from_parts(nodes: Vec<BvhNode>, indices: Vec<u32>, primitives: usize, name: &'static str) -> Self {
        Self { nodes, indices, name, build_ms: 0.0, primitives, spatial_splits: false }
    }

    /// Marks leaves as holding references clipped by spatial splits, which relaxes one check
    /// of [`Bvh::validate`].
    pub fn with_spatial_splits(mut self) -> Self {
        self.spatial_splits = true;
        self
    }

    pub fn root_bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds())
    }

    pub fn stats(&self) -> AccelStats {
        let mut s = AccelStats {
            name: self.name.into(),
            build_ms: self.build_ms,
            primitives: self.primitives,
            memory_bytes: self.nodes.len() * std::mem::size_of::<BvhNode>() + self.indices.len() * 4,
            ..Default::default()
        };
        traverse::tree_stats(&self.nodes, &mut s, |n| n.bounds().half_area() as f64);
        s
    }

    pub fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        let err = |m: String| Err(ValidationError::new(self.name, m));
        if prims.len() != self.primitives {
            return err(format!("built for {} primitives, given {}", self.primitives, prims.len()));
        }
        if self.nodes.is_empty() {
            return if prims.is_empty() { Ok(()) } else { err("no nodes for a non-empty scene".into()) };
        }
        let mut seen = vec![0u32; prims.len()];
        let mut reached = vec![false; self.nodes.len()];
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            if reached[i] {
                return err(format!("node {i} reached twice"));
            }
            reached[i] = true;
            let n = &self.nodes[i];
            let b = n.bounds();
            if n.is_leaf() {
                let (first, count) = (n.left_first as usize, n.count as usize);
                if first + count > self.indices.len() {
                    return err(format!("leaf {i} points past the index array"));
                }
                for &p in &self.indices[first..first + count] {
                    if p as usize >= prims.len() {
                        return err(format!("leaf {i} holds primitive {p} of {}", prims.len()));
                    }
                    seen[p as usize] += 1;
                    // With spatial splits a leaf bounds only the part of a primitive on its
                    // side of the planes above it (Stich et al. 2009), so the primitive may
                    // stick out; it must still touch the leaf. Without them it lies inside.
                    let pb = prims.bounds(p);
                    if self.spatial_splits && pb.intersection(b).is_empty() {
                        return err(format!("primitive {p} does not touch leaf {i}"));
                    }
                    if !self.spatial_splits && !b.contains_box(&pb) {
                        return err(format!("primitive {p} sticks out of leaf {i}"));
                    }
                }
            } else {
                let l = n.left_first as usize;
                if l + 1 >= self.nodes.len() || l <= i {
                    return err(format!("node {i} has children {l}, {} out of order or range", l + 1));
                }
                for c in [l, l + 1] {
                    if !b.contains_box(&self.nodes[c].bounds()) {
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
        Ok(())
    }
}
