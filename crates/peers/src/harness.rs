//! Tracing a ray set through any [`Peer`] (raylab's structures included), in parallel on the
//! current rayon pool, keeping every ray's answer and timing wall clock and CPU.

use std::time::Instant;

use rayon::prelude::*;
use raylab_core::Ray;

use crate::cpu_time::process_cpu_seconds;
use crate::{Peer, PeerHit, PACKET};

/// Rays per rayon task, as raylab's own `trace` uses.
const CHUNK: usize = 1024;

/// How long one pass over a ray set took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timing {
    pub wall_s: f64,
    /// CPU seconds of the whole process during the pass (0 where unavailable).
    pub cpu_s: f64,
}

fn timed(f: impl FnOnce()) -> Timing {
    let cpu0 = process_cpu_seconds();
    let start = Instant::now();
    f();
    let wall_s = start.elapsed().as_secs_f64();
    let cpu_s = match (cpu0, process_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => 0.0,
    };
    Timing { wall_s, cpu_s }
}

/// Closest hits of `rays` into `out` (same length).
pub fn closest(peer: &dyn Peer, rays: &[Ray], out: &mut [Option<PeerHit>]) -> Timing {
    timed(|| {
        out.par_chunks_mut(CHUNK).zip(rays.par_chunks(CHUNK)).for_each(|(o, r)| {
            for (o, r) in o.iter_mut().zip(r) {
                *o = peer.intersect(r);
            }
        })
    })
}

/// Any-hit answers of `rays` into `out` (same length).
pub fn occluded(peer: &dyn Peer, rays: &[Ray], out: &mut [bool]) -> Timing {
    timed(|| {
        out.par_chunks_mut(CHUNK).zip(rays.par_chunks(CHUNK)).for_each(|(o, r)| {
            for (o, r) in o.iter_mut().zip(r) {
                *o = peer.occluded(r);
            }
        })
    })
}

/// Closest hits of `rays` in packets: `packets` are consecutive ranges of at most
/// [`PACKET`] rays covering `rays` (see [`TilePackets`]).
pub fn closest_packets(peer: &dyn Peer, rays: &[Ray], packets: &[(u32, u32)], out: &mut [Option<PeerHit>]) -> Timing {
    assert_eq!(rays.len(), out.len());
    // Split `out` along the packets so that each task owns its packets' answers.
    let mut slices = Vec::with_capacity(packets.len());
    let mut rest = out;
    let mut at = 0u32;
    for &(start, end) in packets {
        assert!(start == at && end - start <= PACKET as u32, "packets must cover the rays in order");
        let (head, tail) = std::mem::take(&mut rest).split_at_mut((end - start) as usize);
        slices.push((&rays[start as usize..end as usize], head));
        rest = tail;
        at = end;
    }
    assert!(rest.is_empty(), "packets must cover every ray");
    timed(|| {
        slices.par_chunks_mut(CHUNK / PACKET).for_each(|chunk| {
            for (r, o) in chunk.iter_mut() {
                peer.intersect16(r, o);
            }
        })
    })
}

/// Camera rays regrouped into 4×4 pixel tiles, one packet per tile (Embree's and tinybvh's
/// choice for coherent primary rays): `order[k]` is the row-major index of the `k`-th ray in
/// tile order, and `packets` the ranges of `order` forming each tile (smaller at the right
/// and bottom edges).
#[derive(Clone, Debug, PartialEq)]
pub struct TilePackets {
    pub order: Vec<u32>,
    pub packets: Vec<(u32, u32)>,
}

impl TilePackets {
    pub fn new(width: u32, height: u32) -> Self {
        let (mut order, mut packets) = (Vec::with_capacity((width * height) as usize), Vec::new());
        for ty in (0..height).step_by(4) {
            for tx in (0..width).step_by(4) {
                let start = order.len() as u32;
                for y in ty..(ty + 4).min(height) {
                    for x in tx..(tx + 4).min(width) {
                        order.push(y * width + x);
                    }
                }
                packets.push((start, order.len() as u32));
            }
        }
        Self { order, packets }
    }

    /// `items` (row-major) in tile order.
    pub fn reorder<T: Copy>(&self, items: &[T]) -> Vec<T> {
        self.order.iter().map(|&i| items[i as usize]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raylab_core::Vec3;

    #[test]
    fn tiles_cover_every_pixel_once_in_4x4_blocks() {
        let t = TilePackets::new(6, 5);
        // Tiles: (0..4, 0..4) 16 rays, (4..6, 0..4) 8, (0..4, 4..5) 4, (4..6, 4..5) 2.
        assert_eq!(t.packets, vec![(0, 16), (16, 24), (24, 28), (28, 30)]);
        assert_eq!(&t.order[..6], &[0, 1, 2, 3, 6, 7]);
        assert_eq!(&t.order[16..20], &[4, 5, 10, 11]);
        assert_eq!(&t.order[28..], &[28, 29]);
        let mut seen = t.order.clone();
        seen.sort();
        assert_eq!(seen, (0..30).collect::<Vec<u32>>());
    }

    /// A "structure" that hits everything at t = the ray's x origin, from primitive 0.
    struct Wall;
    impl Peer for Wall {
        fn name(&self) -> String {
            "wall".into()
        }
        fn build_ms(&self) -> f64 {
            0.0
        }
        fn memory_bytes(&self) -> usize {
            0
        }
        fn intersect(&self, ray: &Ray) -> Option<PeerHit> {
            (ray.origin.x > 0.0).then_some(PeerHit { t: ray.origin.x, prim: 0 })
        }
        fn occluded(&self, ray: &Ray) -> bool {
            ray.origin.x > 0.0
        }
    }

    #[test]
    fn every_ray_gets_its_own_answer() {
        let rays: Vec<Ray> = (0..3000).map(|i| Ray::new(Vec3::new(i as f32 - 100.0, 0.0, 0.0), Vec3::X)).collect();
        let want: Vec<Option<PeerHit>> = rays.iter().map(|r| Wall.intersect(r)).collect();
        let mut out = vec![None; rays.len()];
        closest(&Wall, &rays, &mut out);
        assert_eq!(out, want);
        let mut occ = vec![false; rays.len()];
        occluded(&Wall, &rays, &mut occ);
        assert_eq!(occ.iter().filter(|&&o| o).count(), 2899);
        let tiles = TilePackets::new(60, 50);
        let tiled = tiles.reorder(&rays);
        let mut out = vec![None; rays.len()];
        closest_packets(&Wall, &tiled, &tiles.packets, &mut out);
        assert_eq!(out, tiles.reorder(&want));
    }
}
