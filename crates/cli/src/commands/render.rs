//! `raylab render`: a scene in, an image (or a film) out, with a progress bar and a summary.
//! Renders go through `raylab_render::render_tile` pass by pass, so they can be
//! checkpointed, resumed, stopped by a signal or a time limit, and split into tiles or
//! sample ranges whose films `raylab merge` joins into the same bytes as one render.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use raylab_accel::{Accel, Primitives};
use raylab_render::film::atomic::{check_writable, write_atomic};
use raylab_render::film::image_out::{self as image_io, Aov, AovImage};
use raylab_render::film::{Crop, Film, DEFAULT_PASS_SAMPLES};
use raylab_render::render::{film_header, memory_film_header, render_tile, Control, Stop};

use super::image_args::ImageArgs;
use super::scene_args::SceneArgs;

#[derive(Args, Clone, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output: an image (.png 8-bit sRGB, .ppm binary P6, .exr or .pfm linear float) or a
    /// film (.film: the per-pixel sums, for `raylab merge`; required with --tile, --crop, --samples)
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub image: ImageArgs,
    /// AOVs written as layers of one multi-layer -o FILE.exr beside the image, as Cycles and
    /// Mitsuba write them (albedo.RGB, normal.XYZ facing the camera, depth.Z in scene units,
    /// variance.Y of the pixel's luminance estimate), e.g. --aovs albedo,normal,depth,variance
    #[arg(long, value_enum, value_delimiter = ',', value_name = "AOV,...")]
    pub aovs: Vec<Aov>,
    /// No progress bar or summary
    #[arg(short, long)]
    pub quiet: bool,
    /// Print the summary as JSON on stdout (counters included: rays, node visits,
    /// primitive tests, object-box tests)
    #[arg(long)]
    pub json: bool,
    /// Write the film to FILE (atomically) as passes complete, at most every --checkpoint-every
    #[arg(long, value_name = "FILE")]
    pub checkpoint: Option<PathBuf>,
    /// Time between checkpoints: 60s, 10m, 1h, 500ms (a bare number is seconds)
    #[arg(long, value_name = "DURATION", default_value = "60s", value_parser = parse_duration)]
    pub checkpoint_every: Duration,
    /// Continue the render held in a checkpoint (refused if of another scene, settings or version)
    #[arg(long, value_name = "FILE")]
    pub resume: Option<PathBuf>,
    /// Render as many passes as fit in this time, then write a valid image (e.g. 10m)
    #[arg(long, value_name = "DURATION", value_parser = parse_duration)]
    pub time_limit: Option<Duration>,
    /// Render only tile I of N (horizontal bands, numbered from 0) into a .film
    #[arg(long, value_name = "I/N", value_parser = parse_tile, conflicts_with = "crop")]
    pub tile: Option<(u32, u32)>,
    /// Render only the pixels x0 <= x < x1, y0 <= y < y1 into a .film
    #[arg(long, value_name = "x0,y0,x1,y1", value_parser = parse_crop)]
    pub crop: Option<Crop>,
    /// Render only the sample indices A..B (on pass boundaries) into a .film
    #[arg(long, value_name = "A..B", value_parser = parse_samples)]
    pub samples: Option<(u32, u32)>,
    /// Samples per pass: the unit of checkpoints, interruptions and sample ranges (parts to
    /// be merged must use the same)
    #[arg(long, default_value_t = DEFAULT_PASS_SAMPLES, value_parser = clap::value_parser!(u32).range(1..=1048576))]
    pub pass_spp: u32,
}

/// A render stopped by a signal after saving what it had: `main` prints the message and
/// exits with the code (130 for SIGINT, 143 for SIGTERM, the shells' 128 + signal).
#[derive(Debug)]
pub struct Interrupted {
    pub code: u8,
    pub message: String,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Interrupted {}

/// `60s`, `10m`, `2h`, `500ms`, or a bare number of seconds.
pub fn parse_duration(s: &str) -> Result<Duration, String> {
    let (number, unit) = s.find(|c: char| c.is_ascii_alphabetic()).map_or((s, "s"), |i| s.split_at(i));
    let v: f64 = number.trim().parse().map_err(|_| format!("`{s}` is not a duration (e.g. 90s, 10m, 2h, 500ms)"))?;
    let scale = match unit {
        "ms" => 1e-3,
        "s" => 1.0,
        "m" | "min" => 60.0,
        "h" => 3600.0,
        _ => return Err(format!("`{s}`: unknown unit `{unit}` (valid: ms, s, m, h)")),
    };
    let secs = v * scale;
    if !(secs.is_finite() && (0.0..1e9).contains(&secs)) {
        return Err(format!("`{s}` is not a duration between 0 and 10^9 seconds"));
    }
    Ok(Duration::from_secs_f64(secs))
}

fn parse_tile(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("`{s}` is not a tile I/N (e.g. 0/4: the first of four, numbered from 0)");
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (u32, u32) = (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if n == 0 || i >= n {
        return Err(format!("tile {i}/{n}: the index must be below the count (tiles are numbered from 0)"));
    }
    Ok((i, n))
}

fn parse_crop(s: &str) -> Result<Crop, String> {
    let v: Vec<u32> = s.split(',').map(|t| t.trim().parse()).collect::<Result<_, _>>().map_err(|_| format!("`{s}` is not a crop x0,y0,x1,y1 of four pixel coordinates"))?;
    let [x0, y0, x1, y1] = v[..] else { return Err(format!("`{s}` is not a crop x0,y0,x1,y1 of four pixel coordinates")) };
    if x0 >= x1 || y0 >= y1 {
        return Err(format!("crop {s} is empty (it needs x0 < x1 and y0 < y1)"));
    }
    Ok(Crop { x0, y0, x1, y1 })
}

fn parse_samples(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("`{s}` is not a sample range A..B (e.g. 0..64)");
    let (a, b) = s.split_once("..").ok_or_else(bad)?;
    let (a, b): (u32, u32) = (a.trim().parse().map_err(|_| bad())?, b.trim().parse().map_err(|_| bad())?);
    if a >= b {
        return Err(format!("sample range {a}..{b} is empty"));
    }
    Ok((a, b))
}

/// `--aovs` needs one whole image in an EXR, and each AOV once.
fn check_aovs(aovs: &[Aov], out: &Path, partial: bool) -> Result<()> {
    if aovs.is_empty() {
        return Ok(());
    }
    if !out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
        bail!("{}: --aovs writes one multi-layer OpenEXR file: give -o FILE.exr", out.display());
    }
    if partial {
        bail!("--aovs: AOVs are written with the whole image, not with --tile, --crop or --samples");
    }
    if let Some(a) = aovs.iter().enumerate().find_map(|(i, a)| aovs[..i].contains(a).then_some(a)) {
        bail!("--aovs: `{a}` is given twice");
    }
    Ok(())
}

/// Each AOV's image: its integrator rendered with the scene's other settings, or the
/// beauty film's variance. The scene's integrator is back afterwards.
fn render_aovs(scene: &mut raylab_render::Scene, film: &Film, aovs: &[Aov]) -> Vec<AovImage> {
    let beauty = scene.settings.integrator;
    let images = aovs
        .iter()
        .map(|&aov| match aov.integrator() {
            Some(k) => {
                scene.settings.integrator = k;
                AovImage { aov, pixels: raylab_render::render(scene, &|_| {}).pixels }
            }
            None => AovImage { aov, pixels: film.variance().into_iter().map(|v| raylab_core::Rgb::new(v, 0.0, 0.0)).collect() },
        })
        .collect();
    scene.settings.integrator = beauty;
    images
}

/// What `-o` asks for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum OutputKind {
    Image,
    Film,
}

fn output_kind(out: &Path) -> Result<OutputKind> {
    let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "film" => Ok(OutputKind::Film),
        "png" | "ppm" | "exr" | "pfm" => Ok(OutputKind::Image),
        _ => bail!("{}: unknown output format `.{ext}` (valid: {}, film)", out.display(), image_io::image_format_names()),
    }
}

/// Reads a film file: a regular file (never a device such as /dev/zero), named in errors.
pub fn read_film(path: &Path) -> Result<Film> {
    let meta = std::fs::metadata(path).with_context(|| format!("{}: cannot read", path.display()))?;
    if !meta.is_file() {
        bail!("{}: not a regular file", path.display());
    }
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    Film::from_bytes(&bytes).map_err(|e| anyhow!("{}: {e}", path.display()))
}

/// Writes a film atomically.
pub fn write_film(path: &Path, film: &Film) -> Result<()> {
    write_atomic(path, film.to_bytes()).with_context(|| format!("{}: cannot write", path.display()))
}

/// The signal flags: `cancel` stops the render after the pass in flight is dropped; a
/// second signal while `cancel` is set exits at once (signal-hook's conditional shutdown
/// runs before the flag is set, so the first signal only sets it).
struct Signals {
    cancel: Arc<AtomicBool>,
    sigint: Arc<AtomicBool>,
    sigterm: Arc<AtomicBool>,
    ids: Vec<signal_hook::SigId>,
}

impl Signals {
    fn install() -> Result<Self> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        use signal_hook::flag;
        let (cancel, sigint, sigterm) = (Arc::new(AtomicBool::new(false)), Arc::new(AtomicBool::new(false)), Arc::new(AtomicBool::new(false)));
        let mut ids = Vec::new();
        for (sig, code, which) in [(SIGINT, 130, &sigint), (SIGTERM, 143, &sigterm)] {
            ids.push(flag::register_conditional_shutdown(sig, code, Arc::clone(&cancel))?);
            ids.push(flag::register(sig, Arc::clone(which))?);
            ids.push(flag::register(sig, Arc::clone(&cancel))?);
        }
        Ok(Self { cancel, sigint, sigterm, ids })
    }
}

impl Drop for Signals {
    fn drop(&mut self) {
        for id in self.ids.drain(..) {
            signal_hook::low_level::unregister(id);
        }
    }
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
    /// Pixels rendered: `x0,y0,x1,y1`.
    crop: String,
    /// Sample indices the output holds, `A..B`.
    samples: String,
    /// done, cancelled (signal) or time-up.
    stopped: &'a str,
}

pub fn run(a: &RenderArgs) -> Result<()> {
    let out = a.output.clone().unwrap_or_else(crate::default_output);
    let kind = output_kind(&out)?;
    a.image.check()?;
    let partial = a.tile.is_some() || a.crop.is_some() || a.samples.is_some();
    if partial && kind != OutputKind::Film {
        bail!("{}: --tile, --crop and --samples render part of the image: give -o PART.film (join the parts with `raylab merge`)", out.display());
    }
    check_aovs(&a.aovs, &out, partial)?;
    // Every destination is checked before the render, not after it.
    check_writable(&out).map_err(|e| anyhow!("{e}"))?;
    if let Some(c) = &a.checkpoint {
        check_writable(c).map_err(|e| anyhow!("--checkpoint: {e}"))?;
    }
    let resumed = a.resume.as_deref().map(read_film).transpose().context("--resume")?;
    let pool = a.scene.pool()?;
    pool.install(|| {
        let load_start = Instant::now();
        let mut scene = a.scene.load()?;
        let load_s = load_start.elapsed().as_secs_f64();
        if let Some(w) = image_io::lossy_output_warning(&out, scene.settings.integrator) {
            eprintln!("warning: {w}");
        }
        // A copy: the AOVs render the scene with their own integrators.
        let s = scene.settings.clone();
        // Fingerprints only for films that leave the process (checkpoints, parts).
        let keeps_film = a.checkpoint.is_some() || a.resume.is_some() || kind == OutputKind::Film;
        let header = if keeps_film { film_header(&scene, a.pass_spp) } else { memory_film_header(&scene, a.pass_spp) };
        let crop = match (a.tile, a.crop) {
            (Some((i, n)), _) => Crop::tile(s.width, s.height, i, n).map_err(|e| anyhow!("--tile: {e}"))?,
            (None, Some(c)) => {
                c.check(s.width, s.height).map_err(|e| anyhow!("--crop: {e}"))?;
                c
            }
            (None, None) => Crop::full(s.width, s.height),
        };
        let samples = a.samples.map_or(0..s.spp, |(a, b)| a..b);
        header.passes_of(&samples).map_err(|e| anyhow!("--samples: {e}"))?;
        let mut film = match resumed {
            Some(f) => {
                let path = a.resume.as_ref().unwrap().display();
                if let Some(why) = header.mismatch(&f.header) {
                    bail!("--resume {path}: refusing the checkpoint: {why}");
                }
                if f.crop != crop {
                    bail!("--resume {path}: refusing the checkpoint: it holds crop {}, this render is of crop {crop}", f.crop);
                }
                f
            }
            None => {
                // A film's sums (CHANNELS f64 per pixel, twice while passes merge) and the
                // resolved image: refused before allocating when it cannot fit.
                let bytes = (crop.pixels() as u64).checked_mul(2 * raylab_render::film::CHANNELS as u64 * 8 + 16);
                raylab_render::memory_guard::check(&format!("a {}×{} film", crop.width(), crop.height()), bytes).map_err(|e| anyhow!("{e}"))?;
                Film::new(header.clone(), crop)?
            }
        };
        let first_pass = if film.passes().is_empty() { header.passes_of(&samples)?.start } else { film.passes().end };
        let passes_left = header.passes_of(&samples)?.end.saturating_sub(first_pass);
        let bar = if a.quiet { ProgressBar::hidden() } else { ProgressBar::new(crop.pixels() as u64 * passes_left as u64) };
        bar.set_style(ProgressStyle::with_template("{spinner} rendering [{bar:40}] {percent:>3}% {elapsed} (eta {eta})").unwrap().progress_chars("=> "));
        let signals = Signals::install()?;
        let start = Instant::now();
        let control = Control { cancel: &signals.cancel, deadline: a.time_limit.map(|d| start + d), progress: &|n| bar.inc(n) };
        let mut last_checkpoint = Instant::now();
        let stop = render_tile(&scene, &mut film, samples.clone(), &control, |f| -> Result<()> {
            if let Some(c) = &a.checkpoint {
                if last_checkpoint.elapsed() >= a.checkpoint_every {
                    write_film(c, f)?;
                    last_checkpoint = Instant::now();
                }
            }
            Ok(())
        })?;
        let seconds = start.elapsed().as_secs_f64();
        bar.finish_and_clear();
        if let Some(c) = &a.checkpoint {
            write_film(c, &film)?;
        }
        let held = film.samples();
        // A stopped render still writes its image (of the samples it holds). A partial film
        // goes to -o only if there is no checkpoint to hold it: with one, -o PART.film
        // appears only once complete, so job scripts can take its existence for "done".
        let written = !held.is_empty() && (kind == OutputKind::Image || stop == Stop::Done || a.checkpoint.is_none());
        if written {
            match kind {
                OutputKind::Film => write_film(&out, &film)?,
                // A render stopped by a signal skips its AOVs, to exit promptly.
                OutputKind::Image if !a.aovs.is_empty() && stop != Stop::Cancelled => {
                    let aovs = render_aovs(&mut scene, &film, &a.aovs);
                    image_io::write_exr_layers(&out, crop.width(), crop.height(), &film.resolve(), a.image.exposure, &aovs)?;
                }
                OutputKind::Image => a.image.write(&out, crop.width(), crop.height(), &film.resolve())?,
            }
        }
        let stopped = match stop {
            Stop::Done => "done",
            Stop::Cancelled => "cancelled",
            Stop::TimeUp => "time-up",
        };
        let g = &scene.geometry;
        let stats = scene.accel().stats();
        let threads = rayon::current_num_threads();
        let mrays = film.counters.rays as f64 / seconds.max(1e-9) / 1e6;
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
                render_seconds: seconds,
                mrays_per_s: mrays,
                counters: film.counters,
                nonfinite_samples: film.nonfinite_samples,
                output: out.display().to_string(),
                crop: crop.to_string(),
                samples: format!("{}..{}", held.start, held.end),
                stopped,
            };
            println!("{}", serde_json::to_string_pretty(&summary)?);
        }
        let wrote = if held.is_empty() {
            "no pass completed, nothing written".to_string()
        } else if !written {
            format!("{} will be written when complete (samples {}..{} of {} held)", out.display(), held.start, held.end, s.spp)
        } else if held.len() as u32 == s.spp && a.output.is_none() {
            format!("Wrote {} (the default output, replaced if it existed; -o names another)", out.display())
        } else if held.len() as u32 == s.spp {
            format!("Wrote {}", out.display())
        } else {
            format!("Wrote {} holding samples {}..{} ({} of {} per pixel)", out.display(), held.start, held.end, held.len(), s.spp)
        };
        let saved = a.checkpoint.as_ref().map_or(String::new(), |c| format!("; checkpoint {} (continue with --resume {})", c.display(), c.display()));
        if !a.quiet {
            let c = &film.counters;
            let per_ray = |n: u64| n as f64 / c.rays.max(1) as f64;
            let part = if crop == Crop::full(s.width, s.height) { String::new() } else { format!(", crop {crop}") };
            eprintln!(
                "Rendered {} at {}×{}{part}, {} spp ({}), integrator {}, max depth {}: {} primitives ({} triangles, {} spheres, {} curve segments, {} patches), {} lights; \
                 {} acceleration structure built in {:.1} ms after {:.2} s of loading. Traced {:.2} M rays in {:.2} s ({:.2} Mrays/s on {threads} thread{}){}; per ray {:.1} nodes visited and {:.1} primitive tests. {wrote}{saved}.",
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
                c.rays as f64 / 1e6,
                seconds,
                mrays,
                if threads == 1 { "" } else { "s" },
                if film.nonfinite_samples > 0 { format!("; {} non-finite samples dropped", film.nonfinite_samples) } else { String::new() },
                per_ray(c.nodes_visited),
                per_ray(c.prim_tests),
            );
        }
        if stop == Stop::Cancelled {
            let (code, name) = if signals.sigterm.load(Ordering::Relaxed) && !signals.sigint.load(Ordering::Relaxed) { (143, "SIGTERM") } else { (130, "SIGINT") };
            return Err(Interrupted { code, message: format!("interrupted by {name}: {wrote}{saved}") }.into());
        }
        Ok(())
    })
}
