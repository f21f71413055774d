//! `raylab bench`: every chosen structure on the same rays, side by side. Repeats are
//! interleaved between structures (the machine's noise hits them alike), the first pass is
//! a warm-up, medians are reported, and every structure's answers must agree with an
//! oracle or the command fails.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Primitives};
use raylab_lab::bench::{median, BenchReport, BenchResult, Machine, RayFigures};
use raylab_lab::{rayfile, rays, RayKind, TraceResult};
use raylab_lab::report::Thumbnail;
use raylab_loader::image_io::Tonemap;
use raylab_loader::Overrides;
use raylab_render::IntegratorKind;

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
    /// Write the results as JSON (schema in docs/bench.md)
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write a self-contained HTML report with charts and heat maps
    #[arg(long)]
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
    /// Other engines' structures to trace side by side with raylab's: embree, obvhs, bvh
    /// (needs a build with `--features peers,embree`; see scripts/peers.sh)
    #[arg(long)]
    pub peers: Option<String>,
}

pub fn parse_accels(list: &str) -> Result<Vec<AccelKind>> {
    if list == "all" {
        return Ok(AccelKind::ALL.to_vec());
    }
    list.split(',').map(|s| s.trim().parse::<AccelKind>().map_err(|e| anyhow::anyhow!("--accels: {e}"))).collect()
}

pub fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("model name")).and_then(|l| l.split(':').nth(1)).map(|s| s.trim().to_string()))
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

pub fn run(a: &BenchArgs) -> Result<()> {
    if let Some(peers) = &a.peers {
        return super::bench_peers::run(a, peers);
    }
    let accels = parse_accels(&a.accels)?;
    // The outputs are checked before the (long) benchmark, not after it.
    for p in a.json.iter().chain(&a.report) {
        raylab_render::film::atomic::check_writable(p).map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    let kinds: Vec<RayKind> = a.rays.split(',').map(|s| s.trim().parse::<RayKind>().map_err(|e| anyhow::anyhow!("--rays: {e}"))).collect::<Result<_>>()?;
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(t) = a.threads {
        b = b.num_threads(t as usize);
    }
    let pool = b.build()?;
    let scenes: Vec<Option<PathBuf>> = if a.scenes.is_empty() { vec![None] } else { a.scenes.iter().cloned().map(Some).collect() };
    let mut results = Vec::new();
    let mut thumbnails = Vec::new();
    pool.install(|| -> Result<()> {
        for path in &scenes {
            let (r, t) = bench_scene(a, path.as_ref(), &accels, &kinds)?;
            results.extend(r);
            thumbnails.extend(t);
        }
        Ok(())
    })?;
    let report = BenchReport { machine: Machine { cpu: cpu_name(), threads: pool.current_num_threads() }, raylab_version: env!("CARGO_PKG_VERSION").into(), repeats: a.repeats, resolution: a.resolution, results };
    if let Some(p) = &a.json {
        raylab_render::film::atomic::write_atomic(p, serde_json::to_string_pretty(&report)?).with_context(|| format!("{}: cannot write", p.display()))?;
        eprintln!("Wrote {}.", p.display());
    }
    if let Some(p) = &a.report {
        raylab_render::film::atomic::write_atomic(p, raylab_lab::report::html(&report, &thumbnails)).with_context(|| format!("{}: cannot write", p.display()))?;
        eprintln!("Wrote {}.", p.display());
    }
    Ok(())
}

fn bench_scene(a: &BenchArgs, path: Option<&PathBuf>, accels: &[AccelKind], kinds: &[RayKind]) -> Result<(Vec<BenchResult>, Vec<Thumbnail>)> {
    let name = path.map_or("default scene".to_string(), |p| p.display().to_string());
    let o = Overrides { accel: Some(AccelKind::Bvh), ..Default::default() };
    let mut scene = match path {
        Some(p) => raylab_loader::load_scene_or_mesh(p, &o)?,
        None => raylab_loader::default_scene(&o)?,
    };
    let geometry = scene.geometry.clone();
    let prims = &geometry;
    let height = ((a.resolution as f64 * scene.settings.height as f64 / scene.settings.width as f64).round() as u32).max(1);
    let sets = rays::generate(&scene, a.resolution, height, kinds, a.seed);
    if let Some(dir) = &a.dump_rays {
        std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
        let stem = path.and_then(|p| p.file_name()).map_or("default".into(), |s| s.to_string_lossy().replace(".obj.gz", "").replace(".obj", "").replace(".toml", ""));
        for s in &sets {
            rayfile::write(&dir.join(format!("{stem}-{}.rays", s.kind)), &s.rays)?;
        }
    }
    let oracle_kind = if prims.len() <= a.oracle_limit { AccelKind::None } else { AccelKind::Bvh };
    // Structures that test every primitive per ray (per object, for one big mesh) take hours
    // on large scenes: `all` leaves them out there; naming them keeps them in.
    let linear = [AccelKind::None, AccelKind::Aabb];
    let accels: Vec<AccelKind> = if a.accels == "all" && oracle_kind != AccelKind::None {
        eprintln!("{name}: {} primitives, above --oracle-limit: `all` leaves out none and aabb (name them to include them)", prims.len());
        accels.iter().copied().filter(|k| !linear.contains(k)).collect()
    } else {
        accels.to_vec()
    };
    let accels = accels.as_slice();
    let oracle = AnyAccel::build(oracle_kind, prims, &BuildOptions::default());
    let reference: Vec<TraceResult> = sets.iter().map(|s| raylab_lab::trace(&oracle, prims, &s.rays, s.kind.any_hit())).collect();

    let bar = ProgressBar::new((accels.len() * (a.repeats as usize + 2)) as u64);
    bar.set_style(ProgressStyle::with_template("{spinner} {msg} [{bar:30}] {pos}/{len}").unwrap().progress_chars("=> "));
    bar.set_message(format!("benchmarking {name}"));
    // Builds: a median over `repeats` builds, keeping the last structure.
    let mut built = Vec::new();
    for &k in accels {
        let mut times = Vec::new();
        let mut accel = None;
        for _ in 0..a.repeats {
            let x = AnyAccel::build(k, prims, &BuildOptions::default());
            times.push(x.stats().build_ms);
            accel = Some(x);
        }
        let accel = accel.unwrap();
        accel.validate(prims).with_context(|| format!("{name}: {k} failed validation"))?;
        built.push((k, accel, median(times)));
        bar.inc(1);
    }
    // Traces: pass 0 is the warm-up; structures interleave within each pass.
    let mut times: Vec<Vec<Vec<f64>>> = vec![vec![Vec::new(); sets.len()]; built.len()];
    let mut last: Vec<Vec<TraceResult>> = vec![vec![TraceResult::default(); sets.len()]; built.len()];
    for pass in 0..=a.repeats {
        for (i, (_, accel, _)) in built.iter().enumerate() {
            for (j, s) in sets.iter().enumerate() {
                let r = raylab_lab::trace(accel, prims, &s.rays, s.kind.any_hit());
                if pass > 0 {
                    times[i][j].push(r.seconds);
                }
                last[i][j] = r;
            }
            bar.inc(1);
        }
    }
    bar.finish_and_clear();

    let mut out = Vec::new();
    println!("{name}: {} primitives; rays from a {}×{height} camera grid; oracle {oracle_kind}; median of {} passes", prims.len(), a.resolution, a.repeats);
    print!("  {:<14} {:>10} {:>11}", "structure", "build ms", "memory KiB");
    for s in &sets {
        print!(" | {:>8} {:>7} {:>10} {:>9}", s.kind.name(), "Mrays/s", "nodes/ray", "tests/ray");
    }
    println!();
    let mut mismatches = Vec::new();
    for (i, (k, accel, build_ms)) in built.iter().enumerate() {
        let stats = accel.stats();
        let mut rays_out = BTreeMap::new();
        print!("  {:<14} {:>10.2} {:>11.1}", k.name(), build_ms, stats.memory_bytes as f64 / 1024.0);
        for (j, s) in sets.iter().enumerate() {
            let r = last[i][j];
            if !r.agrees_with(&reference[j]) {
                mismatches.push(format!("{k} on {} rays: {} hits, t sum {} (oracle {oracle_kind}: {} hits, t sum {})", s.kind, r.hits, r.t_sum, reference[j].hits, reference[j].t_sum));
            }
            let secs = median(times[i][j].clone());
            let n = r.count.max(1) as f64;
            let fig = RayFigures {
                count: r.count,
                hits: r.hits,
                t_sum: r.t_sum,
                mrays_per_s: r.count as f64 / secs.max(1e-12) / 1e6,
                node_visits_per_ray: r.counters.nodes_visited as f64 / n,
                prim_tests_per_ray: r.counters.prim_tests as f64 / n,
                object_tests_per_ray: r.counters.object_tests as f64 / n,
            };
            print!(" | {:>8} {:>7.2} {:>10.1} {:>9.1}", "", fig.mrays_per_s, fig.node_visits_per_ray, fig.prim_tests_per_ray);
            rays_out.insert(s.kind.name().to_string(), fig);
        }
        println!();
        out.push(BenchResult { scene: name.clone(), primitives: prims.len(), accel: k.name().into(), build_ms: *build_ms, memory_bytes: stats.memory_bytes, stats, rays: rays_out });
    }
    if !mismatches.is_empty() {
        bail!("{name}: answers differ from the oracle:\n  {}", mismatches.join("\n  "));
    }
    drop(built);
    let mut thumbs = Vec::new();
    if a.report.is_some() {
        // Heat maps of nodes visited per camera ray, one per structure.
        let s = &mut scene.settings;
        s.height = ((a.heatmap_width as f64 * s.height as f64 / s.width as f64).round() as u32).max(1);
        s.width = a.heatmap_width;
        s.spp = 1;
        s.integrator = IntegratorKind::Heatmap;
        for &k in accels {
            scene.settings.accel = k;
            scene.build_accel(&BuildOptions::default());
            let img = raylab_render::render(&scene, &|_| {});
            let png = raylab_loader::image_io::encode_png(img.width, img.height, &img.pixels, Tonemap::Clamp, 0.0)?;
            thumbs.push(Thumbnail { scene: name.clone(), accel: k.name().into(), png });
        }
    }
    Ok((out, thumbs))
}
