//! Tracing a ray set through a structure, in parallel, with counters and a checksum.

use std::time::Instant;

use rayon::prelude::*;
use raylab_accel::{Accel, AnyAccel, Counters, Primitives};
use raylab_core::Ray;

/// What tracing a ray set produced. `hits` and `t_sum` identify the answers: two correct
/// structures agree on them exactly (closest hits are the same `f32` distances, summed in
/// the same order).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct TraceResult {
    pub count: u64,
    pub hits: u64,
    pub t_sum: f64,
    pub seconds: f64,
    pub counters: Counters,
}

impl TraceResult {
    pub fn mrays_per_s(&self) -> f64 {
        self.count as f64 / self.seconds.max(1e-12) / 1e6
    }

    /// Whether `self` gave the same answers as `other`.
    pub fn agrees_with(&self, other: &TraceResult) -> bool {
        self.hits == other.hits && self.t_sum == other.t_sum
    }
}

const CHUNK: usize = 1024;

/// Traces `rays` (closest hit, or any hit when `any_hit`), counting node visits and
/// primitive tests. Chunks run in parallel; their sums are combined in chunk order so that
/// `t_sum` does not depend on scheduling.
pub fn trace<P: Primitives + ?Sized>(accel: &AnyAccel, prims: &P, rays: &[Ray], any_hit: bool) -> TraceResult {
    trace_counting(accel, prims, rays, any_hit, true)
}

/// [`trace`] choosing whether to count: without counting, structures that compile their
/// counters out (the wide BVHs) run their fast path and `counters` stays zero but for
/// `rays`. The answers are the same either way.
pub fn trace_counting<P: Primitives + ?Sized>(accel: &AnyAccel, prims: &P, rays: &[Ray], any_hit: bool, count: bool) -> TraceResult {
    if !count {
        let start = Instant::now();
        let parts: Vec<(u64, f64)> = rays
            .par_chunks(CHUNK)
            .map(|chunk| {
                let (mut hits, mut t_sum) = (0u64, 0.0f64);
                for r in chunk {
                    if any_hit {
                        hits += u64::from(accel.occluded_fast(prims, r));
                    } else if let Some(h) = accel.intersect_fast(prims, r) {
                        hits += 1;
                        t_sum += h.t as f64;
                    }
                }
                (hits, t_sum)
            })
            .collect();
        return summed(rays.len(), start.elapsed().as_secs_f64(), parts);
    }
    let start = Instant::now();
    let parts: Vec<(u64, f64, Counters)> = rays
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut c = Counters::default();
            let (mut hits, mut t_sum) = (0u64, 0.0f64);
            for r in chunk {
                if any_hit {
                    if accel.occluded(prims, r, &mut c) {
                        hits += 1;
                    }
                } else if let Some(h) = accel.intersect(prims, r, &mut c) {
                    hits += 1;
                    t_sum += h.t as f64;
                }
            }
            (hits, t_sum, c)
        })
        .collect();
    let seconds = start.elapsed().as_secs_f64();
    let mut out = TraceResult { count: rays.len() as u64, seconds, ..Default::default() };
    for (h, t, c) in parts {
        out.hits += h;
        out.t_sum += t;
        out.counters.merge(&c);
    }
    out
}

/// Closest hits of `rays` traced in packets of `packet` consecutive rays (at most
/// [`raylab_accel::PACKET`]; ray files hold primary rays in 4×4 tiles, so 16 is a tile),
/// without counting. The answers, hence `hits` and `t_sum`, are those of
/// [`trace_counting`]: chunks and sums are the same.
pub fn trace_packets<P: Primitives + ?Sized>(accel: &AnyAccel, prims: &P, rays: &[Ray], packet: usize) -> TraceResult {
    assert!((1..=raylab_accel::PACKET).contains(&packet), "packets of 1 to {} rays", raylab_accel::PACKET);
    let start = Instant::now();
    let parts: Vec<(u64, f64)> = rays
        .par_chunks(CHUNK)
        .map(|chunk| {
            let (mut hits, mut t_sum) = (0u64, 0.0f64);
            let mut out = [None; raylab_accel::PACKET];
            for p in chunk.chunks(packet) {
                accel.intersect_packet(prims, p, &mut out[..p.len()]);
                for h in out[..p.len()].iter().flatten() {
                    hits += 1;
                    t_sum += h.t as f64;
                }
            }
            (hits, t_sum)
        })
        .collect();
    summed(rays.len(), start.elapsed().as_secs_f64(), parts)
}

/// The result of an uncounted trace from its chunks' hits and distance sums, summed in
/// chunk order (so the sum does not depend on the thread count).
fn summed(count: usize, seconds: f64, parts: Vec<(u64, f64)>) -> TraceResult {
    let mut out = TraceResult { count: count as u64, seconds, ..Default::default() };
    out.counters.rays = out.count;
    for (h, t) in parts {
        out.hits += h;
        out.t_sum += t;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use raylab_accel::{AccelKind, BuildOptions, PrimHit};
    use raylab_core::{intersect, Aabb, Vec3};

    /// A 20×20 grid of unit-square halves in the plane z = 0.
    struct Floor(Vec<[Vec3; 3]>);

    impl Primitives for Floor {
        fn len(&self) -> usize {
            self.0.len()
        }
        fn bounds(&self, i: u32) -> Aabb {
            Aabb::from_points(self.0[i as usize])
        }
        fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
            let [a, b, c] = self.0[i as usize];
            intersect::triangle(ray, a, b, c).map(|(t, u, v)| PrimHit { t, u, v })
        }
        fn triangle(&self, i: u32) -> Option<[Vec3; 3]> {
            Some(self.0[i as usize])
        }
    }

    #[test]
    fn fast_path_gives_the_counting_paths_answers() {
        let mut tris = Vec::new();
        for y in 0..20 {
            for x in 0..20 {
                let p = |dx: f32, dy: f32| Vec3::new(x as f32 + dx, y as f32 + dy, 0.0);
                tris.push([p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)]);
                tris.push([p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]);
            }
        }
        let floor = Floor(tris);
        // Rays from z = 2 down onto and beyond the floor: those over it hit at t = 2.
        let rays: Vec<Ray> = (0..3000).map(|k| Ray::new(Vec3::new((k % 60) as f32 * 0.41 - 2.0, (k / 60) as f32 * 0.43 - 1.0, 2.0), -Vec3::Z)).collect();
        for kind in [AccelKind::Bvh, AccelKind::Bvh8] {
            let accel = AnyAccel::build(kind, &floor, &BuildOptions::default());
            for any_hit in [false, true] {
                let counted = trace(&accel, &floor, &rays, any_hit);
                let fast = trace_counting(&accel, &floor, &rays, any_hit, false);
                assert!(counted.agrees_with(&fast), "{kind}: {counted:?} vs {fast:?}");
                if !any_hit {
                    for packet in [1, 7, 16] {
                        let packets = trace_packets(&accel, &floor, &rays, packet);
                        assert!(packets.agrees_with(&fast), "{kind}, packets of {packet}: {packets:?} vs {fast:?}");
                    }
                }
                assert!(counted.counters.nodes_visited > 0);
                assert_eq!(fast.counters.rays, rays.len() as u64);
                let inside = rays.iter().filter(|r| (0.0..=20.0).contains(&r.origin.x) && (0.0..=20.0).contains(&r.origin.y)).count() as u64;
                assert_eq!(counted.hits, inside, "{kind}");
                if !any_hit {
                    assert_eq!(counted.t_sum, 2.0 * inside as f64, "{kind}");
                }
            }
        }
    }
}
