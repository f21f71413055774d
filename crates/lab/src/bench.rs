//! The data a benchmark produces (the JSON schema of docs/bench.md).

use std::collections::BTreeMap;

use raylab_accel::AccelStats;
use serde::Serialize;

#[derive(Serialize, Clone, Debug)]
pub struct RayFigures {
    pub count: u64,
    pub hits: u64,
    pub t_sum: f64,
    pub mrays_per_s: f64,
    pub node_visits_per_ray: f64,
    pub prim_tests_per_ray: f64,
    pub object_tests_per_ray: f64,
}

#[derive(Serialize, Clone, Debug)]
pub struct BenchResult {
    pub scene: String,
    pub primitives: usize,
    pub accel: String,
    pub build_ms: f64,
    pub memory_bytes: usize,
    pub stats: AccelStats,
    pub rays: BTreeMap<String, RayFigures>,
}

#[derive(Serialize, Clone, Debug)]
pub struct Machine {
    pub cpu: String,
    pub threads: usize,
}

#[derive(Serialize, Clone, Debug)]
pub struct BenchReport {
    pub machine: Machine,
    pub raylab_version: String,
    pub repeats: u32,
    pub resolution: u32,
    pub results: Vec<BenchResult>,
}

/// Median of a non-empty list.
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}
