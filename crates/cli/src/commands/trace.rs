//! `raylab trace`: traces a ray file through a scene or mesh and prints the hit count, the
//! sum of hit distances and Mrays/s, so that raylab can be compared with any other library
//! on exactly the same rays.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, BuildQuality, Kernel, Prefetch};
use raylab_loader::Overrides;

#[derive(Args, Clone, Debug)]
pub struct TraceArgs {
    /// Scene file (.toml) or bare mesh (.obj, .obj.gz)
    pub scene: PathBuf,
    /// Ray file: little-endian u64 count, then count × 8 f32 (ox oy oz tmin dx dy dz tmax)
    #[arg(long)]
    pub rays: PathBuf,
    /// Acceleration structure
    #[arg(long, default_value = "bvh")]
    pub accel: String,
    /// Builder under bvh, bvh4 and bvh8: low (LBVH), medium (binned SAH), high (SBVH)
    #[arg(long, default_value = "medium", value_enum)]
    pub build_quality: BuildQuality,
    /// Any-hit (shadow) queries instead of closest hits
    #[arg(long)]
    pub any_hit: bool,
    /// Worker threads (default: all cores)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Timed passes after one warm-up; the median is reported
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub repeats: u32,
    /// Trace closest hits in packets of N consecutive rays traversed together (16 = one
    /// 4×4 tile of the primary rays `raylab bench --dump-rays` writes; wide BVHs only,
    /// other structures trace the packet's rays one by one)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=raylab_accel::PACKET as i64))]
    pub packet: Option<u32>,
    /// Kernels of the wide BVHs (bvh4, bvh8, bvh8-sbvh, bvh8q): the default (simd where the CPU
    /// runs it; avx512 for packets of 8-wide nodes where the CPU runs that), or one forced to
    /// compare them (a kernel the CPU lacks falls back to the next best; all give the same
    /// answers)
    #[arg(long, default_value = "auto", value_enum)]
    pub kernel: KernelArg,
    /// Whether single rays through the wide BVHs prefetch each child they enter or push:
    /// auto (on for structures of 32 MiB and more), on or off (the same answers)
    #[arg(long, default_value = "auto", value_enum)]
    pub prefetch: PrefetchArg,
    /// Print JSON
    #[arg(long)]
    pub json: bool,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelArg {
    Auto,
    Portable,
    /// AVX2 for 8-wide nodes, SSE2 for 4-wide; 8-wide packets ray-major, 8 rays per register
    Simd,
    /// The SIMD kernels compiled for AVX-512F/VL (32 vector registers); 8-wide packets ray-major, 16 rays per register
    Avx512,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrefetchArg {
    Auto,
    On,
    Off,
}

pub fn run(a: &TraceArgs) -> Result<()> {
    let kind: AccelKind = a.accel.parse().map_err(|e| anyhow::anyhow!("--accel: {e}"))?;
    if a.packet.is_some() && a.any_hit {
        anyhow::bail!("--packet traces closest hits only: drop --any-hit or --packet");
    }
    let rays = raylab_lab::rayfile::read(&a.rays)?;
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(t) = a.threads {
        b = b.num_threads(t as usize);
    }
    let pool = b.build()?;
    pool.install(|| -> Result<()> {
        let scene = raylab_loader::load_scene_or_mesh(&a.scene, &Overrides { accel: Some(AccelKind::None), ..Default::default() })?;
        let mut accel = AnyAccel::build(kind, &scene.geometry, &BuildOptions { quality: a.build_quality, ..Default::default() });
        accel = match a.kernel {
            KernelArg::Auto => accel,
            KernelArg::Portable => accel.with_kernel(Kernel::Portable),
            KernelArg::Simd => accel.with_kernel(Kernel::Simd),
            KernelArg::Avx512 => accel.with_kernel(Kernel::Avx512),
        };
        accel = accel.with_prefetch(match a.prefetch {
            PrefetchArg::Auto => Prefetch::Auto,
            PrefetchArg::On => Prefetch::On,
            PrefetchArg::Off => Prefetch::Off,
        });
        let prefetch = accel.prefetches_children().unwrap_or(false) && a.packet.is_none();
        let kernel = if a.packet.is_some() { accel.packet_kernel() } else { accel.kernel() };
        let kernel = kernel.map_or("-".to_string(), |k| format!("{k:?}").to_lowercase());
        let build_ms = accel.stats().build_ms;
        let mut results = Vec::new();
        for _ in 0..=a.repeats {
            // Nothing here prints counters: the fast path, with counting compiled out.
            results.push(match a.packet {
                Some(n) => raylab_lab::trace::trace_packets(&accel, &scene.geometry, &rays, n as usize),
                None => raylab_lab::trace::trace_counting(&accel, &scene.geometry, &rays, a.any_hit, false),
            });
        }
        let mut secs: Vec<f64> = results[1..].iter().map(|r| r.seconds).collect();
        secs.sort_by(f64::total_cmp);
        let r = results[results.len() - 1];
        let seconds = secs[secs.len() / 2];
        let mrays = r.count as f64 / seconds.max(1e-12) / 1e6;
        if a.json {
            println!(
                "{}",
                serde_json::json!({ "rays": r.count, "hits": r.hits, "t_sum": r.t_sum, "seconds": seconds, "mrays_per_s": mrays, "accel": kind.name(), "build_quality": a.build_quality.name(), "build_ms": build_ms, "any_hit": a.any_hit, "packet": a.packet.unwrap_or(1), "kernel": kernel, "prefetch": prefetch, "threads": rayon::current_num_threads() })
            );
        } else {
            let query = match a.packet {
                Some(n) => format!("closest hit, packets of {n}"),
                None if a.any_hit => "any hit".into(),
                None => "closest hit".into(),
            };
            println!("rays {}  hits {}  t_sum {:.6}  {:.2} Mrays/s ({}, {}, {kernel} kernel{}, median of {} on {} threads; built in {build_ms:.1} ms at {} quality)", r.count, r.hits, r.t_sum, mrays, kind, query, if prefetch { ", prefetching" } else { "" }, a.repeats, rayon::current_num_threads(), a.build_quality);
        }
        Ok(())
    })
}
