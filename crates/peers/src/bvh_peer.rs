//! The `bvh` crate (svenstaro/bvh, crates.io): binned SAH over one shape per leaf, built in
//! parallel with its rayon executor and traversed with its stack iterator, which yields
//! every shape whose box the ray enters (the crate has no closest-hit traversal). Its own
//! triangle test culls back faces, so the candidates go through raylab's watertight test:
//! the row measures the crate's tree and traversal.

use std::time::Instant;

use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::{BHShape, BoundingHierarchy};
use bvh::bvh::Bvh;
use raylab_core::{intersect, Ray, Vec3};

use crate::{Peer, PeerHit};

struct Tri {
    v: [Vec3; 3],
    /// raylab's index of the triangle.
    id: u32,
    node: usize,
}

impl Bounded<f32, 3> for Tri {
    fn aabb(&self) -> Aabb<f32, 3> {
        let [a, b, c] = self.v;
        Aabb::with_bounds(a.min(b).min(c).to_array().into(), a.max(b).max(c).to_array().into())
    }
}

impl BHShape<f32, 3> for Tri {
    fn set_bh_node_index(&mut self, i: usize) {
        self.node = i;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

pub struct BvhCratePeer {
    bvh: Bvh<f32, 3>,
    tris: Vec<Tri>,
    build_ms: f64,
}

impl BvhCratePeer {
    pub fn build(tris: &[[Vec3; 3]]) -> Self {
        let start = Instant::now();
        let mut shapes: Vec<Tri> = tris.iter().enumerate().map(|(i, &v)| Tri { v, id: i as u32, node: 0 }).collect();
        let bvh = Bvh::build_par(&mut shapes);
        Self { bvh, tris: shapes, build_ms: start.elapsed().as_secs_f64() * 1e3 }
    }

    fn query(ray: &Ray) -> bvh::ray::Ray<f32, 3> {
        bvh::ray::Ray::new(ray.origin.to_array().into(), ray.dir.to_array().into())
    }
}

impl Peer for BvhCratePeer {
    fn name(&self) -> String {
        "bvh crate".into()
    }
    fn build_ms(&self) -> f64 {
        self.build_ms
    }
    fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.bvh.nodes.as_slice()) + std::mem::size_of_val(self.tris.as_slice())
    }
    fn intersect(&self, ray: &Ray) -> Option<PeerHit> {
        let q = Self::query(ray);
        let mut best: Option<PeerHit> = None;
        let mut r = *ray;
        for tri in self.bvh.traverse_iterator(&q, &self.tris) {
            let [a, b, c] = tri.v;
            if let Some((t, _, _)) = intersect::triangle(&r, a, b, c) {
                best = Some(PeerHit { t, prim: tri.id });
                r.t_max = t;
            }
        }
        best
    }
    fn occluded(&self, ray: &Ray) -> bool {
        let q = Self::query(ray);
        self.bvh.traverse_iterator(&q, &self.tris).any(|tri| intersect::triangle(ray, tri.v[0], tri.v[1], tri.v[2]).is_some())
    }
}
