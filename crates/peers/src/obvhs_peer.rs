//! obvhs (crates.io): its compressed wide BVH (CWBVH, Ylitie et al. 2017) and its binary
//! BVH, both from its PLOC builder with reinsertion, `medium_build` preset ("about
//! Embree's build time", its documentation says), traced with its own traversal and its
//! own triangle test, as its examples do. The triangles are copied in the BVH's primitive
//! order (its `cornell_box_cwbvh` example) so that a leaf reads them without indirection.

use std::time::{Duration, Instant};

use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray as ORay, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use raylab_core::{Ray, Vec3};

use crate::{Peer, PeerHit};

enum Tree {
    Cw(CwBvh),
    Two(Bvh2),
}

pub struct ObvhsPeer {
    tree: Tree,
    /// The triangles in the tree's primitive order.
    tris: Vec<Triangle>,
    /// raylab's index of each of them.
    ids: Vec<u32>,
    build_ms: f64,
}

fn triangles(tris: &[[Vec3; 3]]) -> Vec<Triangle> {
    tris.iter().map(|t| Triangle { v0: t[0].to_array().into(), v1: t[1].to_array().into(), v2: t[2].to_array().into() }).collect()
}

fn to_obvhs(ray: &Ray) -> ORay {
    ORay::new(ray.origin.to_array().into(), ray.dir.to_array().into(), ray.t_min, ray.t_max)
}

impl ObvhsPeer {
    pub fn build_cwbvh(tris: &[[Vec3; 3]]) -> Self {
        let start = Instant::now();
        let input = triangles(tris);
        let bvh = build_cwbvh_from_tris(&input, BvhBuildParams::medium_build(), &mut Duration::default());
        let ids = bvh.primitive_indices.clone();
        Self::finish(Tree::Cw(bvh), &input, ids, start)
    }

    pub fn build_bvh2(tris: &[[Vec3; 3]]) -> Self {
        let start = Instant::now();
        let input = triangles(tris);
        let bvh = build_bvh2_from_tris(&input, BvhBuildParams::medium_build(), &mut Duration::default());
        let ids = bvh.primitive_indices.clone();
        Self::finish(Tree::Two(bvh), &input, ids, start)
    }

    fn finish(tree: Tree, input: &[Triangle], ids: Vec<u32>, start: Instant) -> Self {
        let tris = ids.iter().map(|&i| input[i as usize]).collect();
        Self { tree, tris, ids, build_ms: start.elapsed().as_secs_f64() * 1e3 }
    }
}

impl Peer for ObvhsPeer {
    fn name(&self) -> String {
        match self.tree {
            Tree::Cw(_) => "obvhs cwbvh".into(),
            Tree::Two(_) => "obvhs bvh2".into(),
        }
    }
    fn build_ms(&self) -> f64 {
        self.build_ms
    }
    fn memory_bytes(&self) -> usize {
        let nodes = match &self.tree {
            Tree::Cw(b) => std::mem::size_of_val(b.nodes.as_slice()),
            Tree::Two(b) => std::mem::size_of_val(b.nodes.as_slice()),
        };
        // Nodes, the reordered triangles and the map back to raylab's ids; the primitive
        // index list the tree keeps is that map.
        nodes + std::mem::size_of_val(self.tris.as_slice()) + std::mem::size_of_val(self.ids.as_slice())
    }
    fn intersect(&self, ray: &Ray) -> Option<PeerHit> {
        let mut hit = RayHit::none();
        let f = |r: &ORay, id: usize| self.tris[id].intersect(r);
        let found = match &self.tree {
            Tree::Cw(b) => b.ray_traverse(to_obvhs(ray), &mut hit, f),
            Tree::Two(b) => b.ray_traverse(to_obvhs(ray), &mut hit, f),
        };
        found.then(|| PeerHit { t: hit.t, prim: self.ids[hit.primitive_id as usize] })
    }
    fn occluded(&self, ray: &Ray) -> bool {
        let f = |r: &ORay, id: usize| self.tris[id].intersect(r);
        !match &self.tree {
            Tree::Cw(b) => b.ray_traverse_miss(to_obvhs(ray), f),
            Tree::Two(b) => b.ray_traverse_miss(to_obvhs(ray), f),
        }
    }
}
