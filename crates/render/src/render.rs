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
use raylab_accel::{Counters, PACKET};
use raylab_core::{Ray, Rgb, Vec2};

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
    // Camera rays go in 4×4 packets where the structure traverses them together.
    let packets = scene.accel().has_packets() && scene.settings.integrator.traces_ahead();
    // Per tile, unless stopped: its pixel sums, traversal counters and sample count.
    type TileSums = Option<(Vec<[f64; CHANNELS]>, Counters, u64)>;
    let done: Vec<TileSums> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            if stopped() {
                return None;
            }
            let (x1, y1) = ((x0 + TILE).min(crop.x1), (y0 + TILE).min(crop.y1));
            let mut c = Counters::default();
            let mut bad = 0u64;
            let px = if packets { tile_sums_packets(scene, (x0, y0, x1, y1), samples.clone(), &mut c, &mut bad) } else { tile_sums(scene, (x0, y0, x1, y1), samples.clone(), &mut c, &mut bad) };
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

/// A tile's pixels (`x0..x1` × `y0..y1`, row by row): the sums over each pixel's samples
/// `samples`, in index order. Non-finite samples are counted in `bad` and left out.
fn tile_sums(scene: &Scene, (x0, y0, x1, y1): (u32, u32, u32, u32), samples: Range<u32>, c: &mut Counters, bad: &mut u64) -> Vec<[f64; CHANNELS]> {
    let s = &scene.settings;
    let mut px = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
    for y in y0..y1 {
        for x in x0..x1 {
            let mut sum = [0.0f64; CHANNELS];
            for i in samples.clone() {
                let (ray, mut sampler) = camera_ray(scene, x, y, i);
                add_sample(&mut sum, s.integrator.radiance(scene, &ray, &mut sampler, c), bad);
            }
            px.push(sum);
        }
    }
    px
}

/// [`tile_sums`] with the camera rays of each 4×4 block of the tile traced together as one
/// packet per sample index. Each pixel's samples keep their random streams and their order,
/// and packets find the hits single rays find, so the sums are the same bit for bit.
fn tile_sums_packets(scene: &Scene, (x0, y0, x1, y1): (u32, u32, u32, u32), samples: Range<u32>, c: &mut Counters, bad: &mut u64) -> Vec<[f64; CHANNELS]> {
    const SIDE: u32 = 4;
    const { assert!((SIDE * SIDE) as usize == PACKET) };
    let s = &scene.settings;
    let tw = x1 - x0;
    let mut px = vec![[0.0f64; CHANNELS]; (tw * (y1 - y0)) as usize];
    let mut block: Vec<(u32, u32)> = Vec::with_capacity(PACKET);
    let mut rays: Vec<Ray> = Vec::with_capacity(PACKET);
    let mut samplers: Vec<PixelSampler> = Vec::with_capacity(PACKET);
    let mut hits = [None; PACKET];
    for by in (y0..y1).step_by(SIDE as usize) {
        for bx in (x0..x1).step_by(SIDE as usize) {
            block.clear();
            block.extend((by..(by + SIDE).min(y1)).flat_map(|y| (bx..(bx + SIDE).min(x1)).map(move |x| (x, y))));
            for i in samples.clone() {
                rays.clear();
                samplers.clear();
                for &(x, y) in &block {
                    let (ray, sampler) = camera_ray(scene, x, y, i);
                    rays.push(ray);
                    samplers.push(sampler);
                }
                let hits = &mut hits[..block.len()];
                scene.intersect_packet(&rays, hits, c);
                for (k, &(x, y)) in block.iter().enumerate() {
                    let l = s.integrator.radiance_traced(scene, &rays[k], hits[k].take(), &mut samplers[k], c);
                    add_sample(&mut px[((y - y0) * tw + x - x0) as usize], l, bad);
                }
            }
        }
    }
    px
}

/// Sample `i` of pixel (`x`, `y`): its camera ray, its film position drawn from the pixel
/// filter, and the sampler the integrator goes on with.
fn camera_ray(scene: &Scene, x: u32, y: u32, i: u32) -> (Ray, PixelSampler) {
    let s = &scene.settings;
    let inv = Vec2::new(1.0 / s.width as f32, 1.0 / s.height as f32);
    let mut sampler = PixelSampler::new(s.sampler, s.spp, s.seed, x, y, i);
    let film = (Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + s.filter.offset(sampler.pixel_2d())) * inv;
    let ray = scene.camera.ray(film, sampler.get_2d());
    (ray, sampler)
}

/// Adds a sample's radiance to a pixel's sums (RGB and squared luminance), or counts it in
/// `bad` if it is not finite.
fn add_sample(sum: &mut [f64; CHANNELS], l: Rgb, bad: &mut u64) {
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

#[cfg(test)]
mod tests {
    use raylab_accel::{AccelKind, BuildOptions};
    use raylab_core::{Rgb, Transform, Vec3};

    use super::*;
    use crate::integrator::IntegratorKind;
    use crate::light::Light;
    use crate::material::{Material, TexColor};
    use crate::shape::{Sphere, TriangleMesh};
    use crate::{Camera, RenderSettings};

    /// A wavy 24 × 24 height field (1,152 triangles), a mirror sphere, an emitting sphere and a
    /// point light: camera rays hit triangles, spheres (not in triangle blocks) and nothing.
    fn scene(integrator: IntegratorKind, accel: AccelKind) -> Scene {
        let camera = Camera::new(Vec3::new(0.0, 2.0, 3.5), Vec3::ZERO, Vec3::Y, 50.0, 1.0, 0.0, None).unwrap();
        let settings = RenderSettings { width: 29, height: 21, spp: 3, max_depth: 4, integrator, accel, ..Default::default() };
        let mut scene = Scene::new(camera, settings);
        let ground = scene.add_material("ground", Material::Diffuse { albedo: TexColor::Constant(Rgb::new(0.7, 0.6, 0.5)) });
        let mirror = scene.add_material("mirror", Material::Mirror { reflectance: TexColor::Constant(Rgb::splat(0.9)) });
        let n = 24u32;
        let p = |i: u32, j: u32| {
            let (x, z) = (i as f32 / n as f32 * 3.0 - 1.5, j as f32 / n as f32 * 3.0 - 1.5);
            Vec3::new(x, 0.15 * (3.0 * x).sin() * (2.0 * z).cos(), z)
        };
        let positions = (0..=n).flat_map(|j| (0..=n).map(move |i| p(i, j))).collect();
        let v = |i: u32, j: u32| j * (n + 1) + i;
        let indices = (0..n).flat_map(|j| (0..n).flat_map(move |i| [[v(i, j), v(i, j + 1), v(i + 1, j)], [v(i + 1, j), v(i, j + 1), v(i + 1, j + 1)]])).collect();
        scene.geometry.add_mesh(TriangleMesh { name: "ground".into(), positions, indices, material: ground, ..Default::default() });
        scene.geometry.add_sphere(Sphere { center: Vec3::new(0.3, 0.5, 0.0), radius: 0.4, to_world: Transform::IDENTITY, material: mirror, emission: Rgb::ZERO });
        scene.geometry.add_sphere(Sphere { center: Vec3::new(-0.8, 1.2, -0.5), radius: 0.2, to_world: Transform::IDENTITY, material: ground, emission: Rgb::splat(8.0) });
        scene.lights.push(Light::Point { position: Vec3::new(1.0, 3.0, 1.0), intensity: Rgb::splat(10.0) });
        scene.build_accel(&BuildOptions::default());
        scene
    }

    /// Camera rays traced in packets give the pixels of camera rays traced one by one, bit for
    /// bit, on a tile whose 4 × 4 blocks are cut at its right and bottom edges.
    #[test]
    fn packets_give_the_single_ray_sums() {
        let tile = (2, 1, 29, 20);
        for integrator in [IntegratorKind::Path, IntegratorKind::Whitted, IntegratorKind::Direct, IntegratorKind::Albedo, IntegratorKind::Normals, IntegratorKind::Depth] {
            for accel in [AccelKind::Bvh8, AccelKind::Bvh4, AccelKind::Bvh8Q] {
                let scene = scene(integrator, accel);
                assert!(scene.accel().has_packets() && integrator.traces_ahead());
                let (mut c1, mut c16, mut bad1, mut bad16) = (Counters::default(), Counters::default(), 0, 0);
                let single = tile_sums(&scene, tile, 0..3, &mut c1, &mut bad1);
                let packets = tile_sums_packets(&scene, tile, 0..3, &mut c16, &mut bad16);
                assert_eq!(single.len(), 27 * 19);
                let bits = |px: &[[f64; CHANNELS]]| px.iter().flat_map(|p| p.map(f64::to_bits)).collect::<Vec<_>>();
                assert_eq!(bits(&packets), bits(&single), "{integrator}/{accel}");
                assert_eq!((bad16, bad1), (0, 0));
                // The same rays (camera rays and every later one), the camera rays' nodes
                // counted in packets instead.
                assert_eq!(c16.rays, c1.rays, "{integrator}/{accel}");
                assert!(c16.rays >= 3 * 27 * 19 && c16.nodes_visited > 0, "{integrator}/{accel}");
                // Not a blank image: hits of every kind took part.
                let lit = single.iter().filter(|p| p[0] > 0.0).count();
                assert!(lit > single.len() / 4, "{integrator}/{accel}: {lit} pixels lit");
            }
        }
    }

    /// Heat maps show a single ray's own traversal cost, so they never use packets; other
    /// structures trace camera rays one by one.
    #[test]
    fn packets_only_where_they_apply() {
        assert!(!IntegratorKind::Heatmap.traces_ahead() && !IntegratorKind::HeatmapTests.traces_ahead());
        assert!(!scene(IntegratorKind::Path, AccelKind::Bvh).accel().has_packets());
    }
}
