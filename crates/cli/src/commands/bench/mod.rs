//! `raylab bench`: every chosen structure on the same rays, side by side. The method (shared
//! rays, oracle, interleaved timed passes, medians) is the lab's (`raylab_lab::sweep`); this
//! command parses options, shows progress, runs the whole job list or one shard of it, merges
//! shards, and writes the files. `--peers` runs `peers.rs` instead: raylab against Embree,
//! obvhs and the `bvh` crate on the same rays.

mod peers;

use std::path::PathBuf;
use std::sync::Mutex;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use raylab_lab::bench::{table, BenchReport, BenchResult, SceneSummary};
use raylab_lab::merge::{merge, read_part};
use raylab_lab::sweep::{self, BenchSettings, Progress, Shard};

#[derive(Args, Clone, Debug)]
pub struct BenchArgs {
    /// Scene files (.toml) or bare meshes (.obj, .obj.gz); the default scene when none
    pub scenes: Vec<PathBuf>,
    /// Comma-separated structures, or `all` (which leaves out `none` and `aabb` on scenes
    /// above --oracle-limit primitives)
    #[arg(long, default_value = "all")]
    pub accels: String,
    /// Comma-separated ray sets: primary, diffuse, shadow
    #[arg(long, default_value = "primary,diffuse,shadow")]
    pub rays: String,
    /// Width of the primary-ray grid (height follows the scene's aspect ratio)
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub resolution: u32,
    /// Worker threads (default: all cores)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Timed passes after the warm-up; medians are reported
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub repeats: u32,
    /// Reference for the answers: `none` (brute force) below this many primitives, `bvh` above
    #[arg(long, default_value_t = 20_000)]
    pub oracle_limit: usize,
    /// Write the results as JSON to FILE (schema in docs/bench.md). `--json FILE` is the older
    /// spelling and keeps working; `--json-out` says that it takes a path, where `--json`
    /// elsewhere is a flag that prints JSON
    #[arg(long = "json-out", alias = "json", value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Write a self-contained HTML report with charts and heat maps
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Width of the heat-map thumbnails in the report
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(8..=4096))]
    pub heatmap_width: u32,
    /// Write the generated ray sets to this folder as ray files (see `raylab trace`)
    #[arg(long)]
    pub dump_rays: Option<PathBuf>,
    /// Seed of the diffuse and shadow rays
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Other engines' structures to trace side by side with raylab's: embree (HIGH, MEDIUM
    /// and HIGH robust; one alone as embree-medium or embree-robust), obvhs, bvh (needs a
    /// build with `--features peers,embree`; see scripts/peers.sh)
    #[arg(long)]
    pub peers: Option<String>,
    /// Run only the I-th of N shards of the job list (scene × structure × ray set, in that
    /// order, cut into N contiguous blocks); write the part with --json-out and merge the
    /// parts with --merge
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Merge the parts of a sharded run (their --json-out files) into one result: they must
    /// share raylab version and settings and hold every job exactly once. Writes --json-out
    /// and --report as an unsharded run does
    #[arg(long, value_name = "PART", num_args = 1.., conflicts_with_all = ["scenes", "shard", "dump_rays"])]
    pub merge: Vec<PathBuf>,
}

/// The sweep's progress as a bar on the terminal, and each scene's table when it is done.
struct Terminal {
    bar: Mutex<Option<ProgressBar>>,
}

impl Progress for Terminal {
    fn start_scene(&self, name: &str, steps: u64) {
        let bar = ProgressBar::new(steps);
        bar.set_style(ProgressStyle::with_template("{spinner} {msg} [{bar:30}] {pos}/{len}").unwrap().progress_chars("=> "));
        bar.set_message(format!("benchmarking {name}"));
        *self.bar.lock().unwrap() = Some(bar);
    }
    fn step(&self) {
        if let Some(b) = &*self.bar.lock().unwrap() {
            b.inc(1);
        }
    }
    fn scene_done(&self, summary: &SceneSummary, results: &[BenchResult]) {
        if let Some(b) = self.bar.lock().unwrap().take() {
            b.finish_and_clear();
        }
        print!("{}", table(summary, results));
    }
    fn note(&self, text: &str) {
        eprintln!("{text}");
    }
}

pub fn run(a: &BenchArgs) -> Result<()> {
    if let Some(peers) = &a.peers {
        return peers::run(a, peers);
    }
    // The outputs are checked before the (long) benchmark, not after it.
    for p in a.json.iter().chain(&a.report) {
        raylab_render::film::atomic::check_writable(p).map_err(|e| anyhow!("{e}"))?;
    }
    if a.shard.is_some() && a.json.is_none() {
        bail!("--shard: give --json-out FILE for the part (merge the parts with --merge)");
    }
    let report = if a.merge.is_empty() { measure(a)? } else { merge(&a.merge.iter().map(|p| read_part(p)).collect::<Result<Vec<_>, _>>().map_err(|e| anyhow!(e))?).map_err(|e| anyhow!(e))? };
    if !a.merge.is_empty() {
        println!("merged {} parts: {} jobs, {} results", a.merge.len(), report.jobs.total, report.results.len());
    }
    write(a, &report)
}

/// Runs the job list, or the shard of it that --shard names.
fn measure(a: &BenchArgs) -> Result<BenchReport> {
    let scenes = if a.scenes.is_empty() { vec![None] } else { a.scenes.iter().cloned().map(Some).collect() };
    let mut settings = BenchSettings::new(scenes, &a.accels)?;
    settings.rays = sweep::parse_list::<raylab_lab::RayKind>("--rays", &a.rays)?.iter().map(|k| k.name().to_string()).collect();
    settings.resolution = a.resolution;
    settings.repeats = a.repeats;
    settings.oracle_limit = a.oracle_limit;
    settings.seed = a.seed;
    // A shard records its heat maps: the merge may be asked for a report.
    settings.heatmap_width = (a.report.is_some() || a.shard.is_some()).then_some(a.heatmap_width);
    let all = sweep::jobs(&settings)?;
    let jobs = match a.shard {
        Some(s) => {
            let r = s.range(all.len());
            if r.is_empty() {
                eprintln!("shard {s}: no jobs (the list has {} jobs)", all.len());
            } else {
                eprintln!("shard {s}: jobs {} to {} of {}", r.start, r.end - 1, all.len());
            }
            all[r].to_vec()
        }
        None => all,
    };
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(t) = a.threads {
        b = b.num_threads(t as usize);
    }
    let pool = b.build()?;
    let progress = Terminal { bar: Mutex::new(None) };
    Ok(pool.install(|| sweep::run(&settings, &jobs, a.shard, a.dump_rays.as_deref(), &progress))?)
}

fn write(a: &BenchArgs, report: &BenchReport) -> Result<()> {
    if let Some(p) = &a.json {
        raylab_render::film::atomic::write_atomic(p, serde_json::to_string_pretty(report)?).with_context(|| format!("{}: cannot write", p.display()))?;
        eprintln!("Wrote {}.", p.display());
    }
    if let Some(p) = &a.report {
        raylab_render::film::atomic::write_atomic(p, raylab_lab::report::html(report)).with_context(|| format!("{}: cannot write", p.display()))?;
        eprintln!("Wrote {}.", p.display());
    }
    Ok(())
}
