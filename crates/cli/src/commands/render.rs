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
        if !a.quiet {
            let g = &scene.geometry;
            let stats = scene.accel().stats();
            let threads = rayon::current_num_threads();
            eprintln!(
                "Rendered {} at {}×{}, {} spp ({}), integrator {}, max depth {}: {} primitives ({} triangles, {} spheres), {} lights; \
                 {} acceleration structure built in {:.1} ms after {:.2} s of loading. Traced {:.2} M rays in {:.2} s ({:.2} Mrays/s on {threads} threads){}. Wrote {}.",
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
                scene.lights.len(),
                stats.name,
                stats.build_ms,
                load_s,
                output.counters.rays as f64 / 1e6,
                output.seconds,
                output.mrays_per_second(),
                if output.nonfinite_samples > 0 { format!("; {} non-finite samples dropped", output.nonfinite_samples) } else { String::new() },
                out.display()
            );
        }
        Ok(())
    })
}
