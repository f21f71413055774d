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

/// Traces `rays` (closest hit, or any hit when `any_hit`). Chunks run in parallel; their
/// sums are combined in chunk order so that `t_sum` does not depend on scheduling.
pub fn trace<P: Primitives + ?Sized>(accel: &AnyAccel, prims: &P, rays: &[Ray], any_hit: bool) -> TraceResult {
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
