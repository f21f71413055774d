//! The render loop: [`render_tile`] is the one entry point (plain renders, progressive
//! passes, checkpoints, distributed tiles and sample ranges all call it). It renders a
//! film's crop pass by pass, 16×16 tiles in parallel (rayon), one random stream per pixel
//! sample, so the film is bit-identical whatever the thread count, the tile order, or how
//! the work was split (see [`crate::film`] for the summation order).

use std::fmt::Write as _;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rayon::prelude::*;
use raylab_accel::Counters;
use raylab_core::{Rgb, Vec2};

use crate::film::codec::Fnv64;
use crate::film::{luminance, Crop, Film, FilmError, FilmHeader, CHANNELS, DEFAULT_PASS_SAMPLES};
use crate::sampler::PixelSampler;
use crate::Scene;

pub const TILE: u32 = 16;

/// The raylab version stored in films: a checkpoint of another version is refused, since
/// sampling code may differ between versions.
pub const VERSION: &str = concat!("raylab ", env!("CARGO_PKG_VERSION"), " film ", "1");

/// A rendered image with what it cost.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    /// Linear RGB, row-major, row 0 at the top.
    pub pixels: Vec<Rgb>,
    /// Per pixel, the variance of its estimate of luminance (sample variance / samples): the
    /// `variance` AOV.
    pub variance: Vec<f32>,
    pub counters: Counters,
    /// Samples that came out NaN or infinite and were dropped (counted, never averaged in).
    pub nonfinite_samples: u64,
    pub seconds: f64,
}

impl RenderOutput {
    pub fn mrays_per_second(&self) -> f64 {
        self.counters.rays as f64 / self.seconds.max(1e-9) / 1e6
    }
}

/// How a caller steers [`render_tile`]: stop requests and progress reports.
pub struct Control<'a> {
    /// Set (by a signal handler, a UI, Python's Ctrl-C) to stop: the pass in flight is
    /// dropped, the film keeps the passes completed.
    pub cancel: &'a AtomicBool,
    /// Stop at this instant, dropping the pass in flight (`--time-limit`).
    pub deadline: Option<Instant>,
    /// Called with the number of pixels of each tile as it finishes (once per pass).
    pub progress: &'a (dyn Fn(u64) + Sync),
}

/// Why [`render_tile`] returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// Every requested pass is in the film.
    Done,
    /// `cancel` was set.
    Cancelled,
    /// The deadline passed.
    TimeUp,
}

/// The header of films of `scene` rendered with its settings in passes of `pass_samples`.
pub fn film_header(scene: &Scene, pass_samples: u32) -> FilmHeader {
    FilmHeader { scene_hash: scene_hash(scene), settings_hash: settings_hash(scene, pass_samples), ..memory_film_header(scene, pass_samples) }
}

/// The header of a film that never leaves the process (no checkpoint, no part file): its
/// fingerprints are left at 0, since hashing a large scene costs time for nothing.
pub fn memory_film_header(scene: &Scene, pass_samples: u32) -> FilmHeader {
    let s = &scene.settings;
    FilmHeader { width: s.width, height: s.height, spp: s.spp, pass_samples, scene_hash: 0, settings_hash: 0, version: VERSION.into(), heatmap: s.integrator.is_heatmap() }
}

/// A fingerprint of what the scene contains (not its settings): camera, geometry,
/// materials, textures, lights, background. It hashes the `Debug` text of those parts,
/// which prints every float exactly (shortest round-trip form), streamed into FNV-1a
/// without building the string.
pub fn scene_hash(scene: &Scene) -> u64 {
    let mut h = Fnv64::default();
    let _ = write!(
        h,
        "{:?}{:?}{:?}{:?}{:?}{:?}{:?}{:?}{:?}{:?}",
        scene.camera, scene.geometry, scene.materials, scene.material_names, scene.material_perturbations, scene.textures, scene.texture_names, scene.lights, scene.background, scene.environment
    );
    h.0
}

/// A fingerprint of the render settings (size, samples, sampler, integrator, seed, filter,
/// structure, ...) and the pass size: what decides the bits of the film besides the scene.
pub fn settings_hash(scene: &Scene, pass_samples: u32) -> u64 {
    let mut h = Fnv64::default();
    let _ = write!(h, "{:?} pass {pass_samples}", scene.settings);
    h.0
}

/// Renders the passes of sample range `samples` into `film` (whose header must be the
/// scene's, see [`film_header`]), continuing after the passes it already holds: an empty
/// film starts at `samples.start`, a resumed one must hold a prefix of `samples`.
/// `after_pass` runs after each completed pass (checkpoints); its error stops the render.
pub fn render_tile<E>(scene: &Scene, film: &mut Film, samples: Range<u32>, control: &Control, mut after_pass: impl FnMut(&Film) -> Result<(), E>) -> Result<Stop, E>
where
    E: From<FilmError>,
{
    let want = film.header.passes_of(&samples)?;
    let held = film.passes();
    if !held.is_empty() && (held.start != want.start || held.end > want.end) {
        return Err(FilmError::Invalid(format!("the film holds samples {:?}, which are not a prefix of the samples {:?} asked for", film.samples(), samples)).into());
    }
    let first = if held.is_empty() { want.start } else { held.end };
    for pass in first..want.end {
        if control.cancel.load(Ordering::Relaxed) {
            return Ok(Stop::Cancelled);
        }
        if control.deadline.is_some_and(|d| Instant::now() >= d) {
            return Ok(Stop::TimeUp);
        }
        let Some((sums, counters, bad)) = render_pass(scene, film, pass, control) else {
            return Ok(if control.cancel.load(Ordering::Relaxed) { Stop::Cancelled } else { Stop::TimeUp });
        };
        film.add_pass(pass, sums, &counters, bad)?;
        after_pass(film)?;
    }
    Ok(Stop::Done)
}

/// One pass over the film's crop: per pixel the `f64` sums of the pass's samples (RGB and
/// squared luminance), or `None` if stopped midway (the partial pass is dropped).
fn render_pass(scene: &Scene, film: &Film, pass: u32, control: &Control) -> Option<(Vec<f64>, Counters, u64)> {
    let crop = film.crop;
    let samples = film.header.pass_range(pass);
    let tiles: Vec<(u32, u32)> = (crop.y0..crop.y1).step_by(TILE as usize).flat_map(|y| (crop.x0..crop.x1).step_by(TILE as usize).map(move |x| (x, y))).collect();
    let stopped = || control.cancel.load(Ordering::Relaxed) || control.deadline.is_some_and(|d| Instant::now() >= d);
    let done: Vec<Option<(Vec<[f64; CHANNELS]>, Counters, u64)>> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            if stopped() {
                return None;
            }
            let (x1, y1) = ((x0 + TILE).min(crop.x1), (y0 + TILE).min(crop.y1));
            let mut c = Counters::default();
            let mut bad = 0u64;
            let mut px = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            for y in y0..y1 {
                for x in x0..x1 {
                    px.push(pixel_sums(scene, x, y, samples.clone(), &mut c, &mut bad));
                }
            }
            (control.progress)(px.len() as u64);
            Some((px, c, bad))
        })
        .collect();
    let mut sums = vec![0.0f64; crop.pixels() * CHANNELS];
    let mut counters = Counters::default();
    let mut nonfinite = 0;
    for (&(x0, y0), tile) in tiles.iter().zip(done) {
        let (px, c, bad) = tile?;
        let tw = (x0 + TILE).min(crop.x1) - x0;
        for (k, p) in px.into_iter().enumerate() {
            let (x, y) = (x0 - crop.x0 + k as u32 % tw, y0 - crop.y0 + k as u32 / tw);
            let i = (y * crop.width() + x) as usize * CHANNELS;
            sums[i..i + CHANNELS].copy_from_slice(&p);
        }
        counters.merge(&c);
        nonfinite += bad;
    }
    Some((sums, counters, nonfinite))
}

/// The sums over the pixel's samples `samples`, in index order, their film positions drawn
/// from the pixel filter. Non-finite samples are counted in `bad` and left out.
fn pixel_sums(scene: &Scene, x: u32, y: u32, samples: Range<u32>, c: &mut Counters, bad: &mut u64) -> [f64; CHANNELS] {
    let s = &scene.settings;
    let inv = Vec2::new(1.0 / s.width as f32, 1.0 / s.height as f32);
    let mut sum = [0.0f64; CHANNELS];
    for i in samples {
        let mut sampler = PixelSampler::new(s.sampler, s.spp, s.seed, x, y, i);
        let film = (Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + s.filter.offset(sampler.pixel_2d())) * inv;
        let ray = scene.camera.ray(film, sampler.get_2d());
        let l = s.integrator.radiance(scene, &ray, &mut sampler, c);
        if l.is_finite() {
            let (r, g, b) = (l.x as f64, l.y as f64, l.z as f64);
            sum[0] += r;
            sum[1] += g;
            sum[2] += b;
            sum[3] += luminance(r, g, b).powi(2);
        } else {
            *bad += 1;
        }
    }
    sum
}

/// Renders `scene` with its settings, whole, in passes of [`DEFAULT_PASS_SAMPLES`]: a thin
/// wrapper of [`render_tile`]. `progress(pixels)` is called as tiles finish, once per pass,
/// so it totals `width × height × passes`.
pub fn render(scene: &Scene, progress: &(dyn Fn(u64) + Sync)) -> RenderOutput {
    render_until(scene, progress, &AtomicBool::new(false)).expect("a render that is never cancelled completes")
}

/// [`render`] that stops when `cancel` is set (Python's Ctrl-C, a UI): `None` then, the
/// image of the passes done being of no use to these callers.
pub fn render_until(scene: &Scene, progress: &(dyn Fn(u64) + Sync), cancel: &AtomicBool) -> Option<RenderOutput> {
    let s = &scene.settings;
    let start = Instant::now();
    let empty = || RenderOutput { width: s.width, height: s.height, pixels: vec![Rgb::ZERO; s.width as usize * s.height as usize], variance: vec![0.0; s.width as usize * s.height as usize], counters: Counters::default(), nonfinite_samples: 0, seconds: 0.0 };
    let header = memory_film_header(scene, DEFAULT_PASS_SAMPLES);
    // An empty image or no samples (settings the loader never produces): nothing to render.
    let Ok(mut film) = Film::new(header, Crop::full(s.width, s.height)) else { return Some(empty()) };
    let control = Control { cancel, deadline: None, progress };
    match render_tile(scene, &mut film, 0..s.spp, &control, |_| Ok::<(), FilmError>(())) {
        Ok(Stop::Done) => {}
        Ok(_) => return None,
        Err(_) => return Some(empty()),
    }
    let seconds = start.elapsed().as_secs_f64();
    Some(RenderOutput { width: s.width, height: s.height, pixels: film.resolve(), variance: film.variance(), counters: film.counters, nonfinite_samples: film.nonfinite_samples, seconds })
}
