//! The data a benchmark produces (the JSON schema of docs/bench.md), and its text table.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::PathBuf;

use raylab_accel::AccelStats;
use serde::{Deserialize, Serialize};

#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct RayFigures {
    pub count: u64,
    pub hits: u64,
    pub t_sum: f64,
    pub mrays_per_s: f64,
    pub node_visits_per_ray: f64,
    pub prim_tests_per_ray: f64,
    pub object_tests_per_ray: f64,
}

/// One structure on one scene: its build, and the figures of each ray set it traced.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct BenchResult {
    pub scene: String,
    pub primitives: usize,
    pub accel: String,
    pub build_ms: f64,
    pub memory_bytes: usize,
    pub stats: AccelStats,
    pub rays: BTreeMap<String, RayFigures>,
}

#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Machine {
    pub cpu: String,
    pub threads: usize,
}

/// Nodes visited by each camera ray of a `width × height` grid, for one structure on one
/// scene: the raw counts, so that the report can draw every structure of a scene on one
/// shared scale. `nodes` is base64 of little-endian `u16` counts (saturated at 65,535), row
/// by row from the top.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct HeatmapRecord {
    pub scene: String,
    pub accel: String,
    pub width: u32,
    pub height: u32,
    pub nodes: String,
}

#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct BenchReport {
    pub machine: Machine,
    pub raylab_version: String,
    pub repeats: u32,
    pub resolution: u32,
    pub results: Vec<BenchResult>,
    /// What was asked: the job list follows from it (see [`crate::sweep::jobs`]).
    pub settings: BenchSettings,
    /// Which jobs of the list this report holds.
    pub jobs: JobsRecord,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub heatmaps: Vec<HeatmapRecord>,
}

/// What a sweep measures; the job list follows from it alone, so that every shard of a run
/// computes the same list.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct BenchSettings {
    /// Scene files or bare meshes; `null` stands for the embedded default scene.
    pub scenes: Vec<Option<PathBuf>>,
    /// Structure names, in order.
    pub accels: Vec<String>,
    /// Whether the list was `all`: then `none` and `aabb` are skipped on scenes above
    /// `oracle_limit` primitives.
    pub all: bool,
    /// Ray-set names, in order.
    pub rays: Vec<String>,
    pub resolution: u32,
    pub repeats: u32,
    pub oracle_limit: usize,
    pub seed: u64,
    /// Width of the heat maps (nodes visited per camera ray) to record; none when `null`.
    pub heatmap_width: Option<u32>,
}

/// The `index`-th (from 1) of `count` shards of a job list.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

/// Which jobs of the list a report holds.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct JobsRecord {
    /// Length of the full job list.
    pub total: usize,
    /// The shard this report ran; `null` for a whole run or a merge.
    pub shard: Option<Shard>,
    /// Jobs run, by position in the list.
    pub ran: Vec<usize>,
    /// Jobs left out by the rules of the method, with the reason.
    pub skipped: Vec<SkippedJob>,
}

#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct SkippedJob {
    pub job: usize,
    pub reason: String,
}

/// What a scene's run found out before the timings: printed above its table.
#[derive(Clone, Debug)]
pub struct SceneSummary {
    pub name: String,
    pub primitives: usize,
    pub grid: (u32, u32),
    pub oracle: String,
    pub repeats: u32,
}

/// The text table of one scene's results, as `raylab bench` prints it.
pub fn table(s: &SceneSummary, results: &[BenchResult]) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "{}: {} primitives; rays from a {}×{} camera grid; oracle {}; median of {} passes", s.name, s.primitives, s.grid.0, s.grid.1, s.oracle, s.repeats);
    let kinds: Vec<&String> = results.first().map(|r| r.rays.keys().collect()).unwrap_or_default();
    let _ = write!(t, "  {:<14} {:>10} {:>11}", "structure", "build ms", "memory KiB");
    for k in &kinds {
        let _ = write!(t, " | {:>8} {:>7} {:>10} {:>9}", k, "Mrays/s", "nodes/ray", "tests/ray");
    }
    t.push('\n');
    for r in results {
        let _ = write!(t, "  {:<14} {:>10.2} {:>11.1}", r.accel, r.build_ms, r.memory_bytes as f64 / 1024.0);
        for f in r.rays.values() {
            let _ = write!(t, " | {:>8} {:>7.2} {:>10.1} {:>9.1}", "", f.mrays_per_s, f.node_visits_per_ray, f.prim_tests_per_ray);
        }
        t.push('\n');
    }
    t
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

/// The processor's model name (Linux), else the architecture.
pub fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("model name")).and_then(|l| l.split(':').nth(1)).map(|s| s.trim().to_string()))
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}
