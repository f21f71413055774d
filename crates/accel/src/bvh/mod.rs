//! Bounding volume hierarchy: a binary tree of boxes, flattened into an array of 32-byte
//! nodes with siblings adjacent (tinybvh's layout), traversed front to back.
//!
//! Top-down builders (`build.rs`) differ only in where they split: binned SAH (Wald 2007),
//! object median, spatial midpoint. Other builders produce the same nodes: `lbvh.rs`
//! (Morton codes, Karras 2012), `ploc.rs` (Meister & Bittner 2018) and `sbvh.rs` (spatial
//! splits, Stich et al. 2009); the last two start from `morton.rs`' order. The walk,
//! statistics and validation are the binary-tree code of `tree.rs`, shared with the sphere
//! hierarchy; `traverse.rs` holds only the box test. `prim_ref.rs` holds what the binned
//! and spatial-split builders stream through: a box and its index in 32 bytes.

mod build;
pub mod lbvh;
pub mod morton;
mod node;
pub mod ploc;
mod prim_ref;
mod sah;
pub mod sbvh;
pub(crate) mod traverse;

pub use node::BvhNode;
pub use sah::SahCost;

use raylab_core::Aabb;

use crate::tree::{self, Containment};
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

pub(crate) use crate::tree::MAX_DEPTH;

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
        tree::tree_stats(&self.nodes, &mut s, |n| n.bounds().half_area() as f64);
        s
    }

    pub fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        // With spatial splits a leaf bounds only the part of a primitive on its side of the
        // planes above it (Stich et al. 2009), so the primitive may stick out; it must still
        // touch the leaf, and may be in several. Without them it lies inside one leaf.
        let leaf_holds = |i: usize, n: &BvhNode, p: u32| {
            let (pb, b) = (prims.bounds(p), n.bounds());
            match self.spatial_splits {
                true if pb.intersection(b).is_empty() => Err(format!("primitive {p} does not touch leaf {i}")),
                false if !b.contains_box(&pb) => Err(format!("primitive {p} sticks out of leaf {i}")),
                _ => Ok(()),
            }
        };
        let child_inside = |n: &BvhNode, c: &BvhNode| n.bounds().contains_box(&c.bounds());
        tree::validate_tree(self.name, &self.nodes, &self.indices, self.primitives, prims, Containment { child_inside, leaf_holds, each_once: !self.spatial_splits })
    }
}
