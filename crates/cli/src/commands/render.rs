//! `raylab render`: a scene in, an image out, with a progress bar and a summary.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use raylab_accel::{Accel, Primitives};
use raylab_loader::image_io::{self, Tonemap};

use super::scene_args::SceneArgs;

#[derive(Args, Clone, Debug, Default)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output image: .png (8-bit sRGB), .ppm (binary P6), .exr or .pfm (linear float)
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Tone map for 8-bit outputs: clamp, reinhard or aces
    #[arg(long, default_value = "clamp")]
    pub tonemap: Tonemap,
    /// Exposure in stops applied before tone mapping
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// No progress bar or summary
    #[arg(short, long)]
    pub quiet: bool,
    /// Print the summary as JSON on stdout (counters included: rays, node visits,
    /// primitive tests, object-box tests)
    #[arg(long)]
    pub json: bool,
}

#[derive(serde::Serialize)]
struct Summary<'a> {
    scene: String,
    width: u32,
    height: u32,
    spp: u32,
    accel: &'a str,
    threads: usize,
    primitives: usize,
    build_ms: f64,
    render_seconds: f64,
    mrays_per_s: f64,
    counters: raylab_accel::Counters,
    nonfinite_samples: u64,
    output: String,
}

pub fn run(a: &RenderArgs) -> Result<()> {
    let out = a.output.clone().unwrap_or_else(crate::default_output);
    let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if !["png", "ppm", "exr", "pfm"].contains(&ext.as_str()) {
        bail!("{}: unknown image format `.{ext}` (valid: {})", out.display(), image_io::image_format_names());
    }
    let tonemap = a.tonemap;
    if !a.exposure.is_finite() {
        bail!("--exposure: expected a finite number");
    }
    let pool = a.scene.pool()?;
    pool.install(|| {
        let load_start = Instant::now();
        let scene = a.scene.load()?;
        let load_s = load_start.elapsed().as_secs_f64();
        let s = &scene.settings;
        let bar = if a.quiet { ProgressBar::hidden() } else { ProgressBar::new(s.width as u64 * s.height as u64) };
        bar.set_style(ProgressStyle::with_template("{spinner} rendering [{bar:40}] {percent:>3}% {elapsed} (eta {eta})").unwrap().progress_chars("=> "));
        let output = raylab_render::render(&scene, &|n| bar.inc(n));
        bar.finish_and_clear();
        image_io::write_image(&out, output.width, output.height, &output.pixels, tonemap, a.exposure)?;
        let g = &scene.geometry;
        let stats = scene.accel().stats();
        let threads = rayon::current_num_threads();
        if a.json {
            let summary = Summary {
                scene: a.scene.scene_name(),
                width: s.width,
                height: s.height,
                spp: s.spp,
                accel: &stats.name,
                threads,
                primitives: g.len(),
                build_ms: stats.build_ms,
                render_seconds: output.seconds,
                mrays_per_s: output.mrays_per_second(),
                counters: output.counters,
                nonfinite_samples: output.nonfinite_samples,
                output: out.display().to_string(),
            };
            println!("{}", serde_json::to_string_pretty(&summary)?);
        }
        if !a.quiet {
            let c = &output.counters;
            let per_ray = |n: u64| n as f64 / c.rays.max(1) as f64;
            eprintln!(
                "Rendered {} at {}×{}, {} spp ({}), integrator {}, max depth {}: {} primitives ({} triangles, {} spheres, {} curve segments, {} patches), {} lights; \
                 {} acceleration structure built in {:.1} ms after {:.2} s of loading. Traced {:.2} M rays in {:.2} s ({:.2} Mrays/s on {threads} threads){}; per ray {:.1} nodes visited and {:.1} primitive tests. Wrote {}.",
                a.scene.scene_name(),
                s.width,
                s.height,
                s.spp,
                s.sampler,
                s.integrator,
                s.max_depth,
                g.len(),
                g.triangle_count(),
                g.spheres.len(),
                g.curves.iter().map(|c| c.len()).sum::<usize>(),
                g.patch_sets.iter().map(|p| p.len()).sum::<usize>(),
                scene.lights.len() + scene.area_lights.len() + scene.environment.is_some() as usize,
                stats.name,
                stats.build_ms,
                load_s,
                output.counters.rays as f64 / 1e6,
                output.seconds,
                output.mrays_per_second(),
                if output.nonfinite_samples > 0 { format!("; {} non-finite samples dropped", output.nonfinite_samples) } else { String::new() },
                per_ray(c.nodes_visited),
                per_ray(c.prim_tests),
                out.display()
            );
        }
        Ok(())
    })
}
