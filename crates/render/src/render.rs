//! The render loop: tiles in parallel (rayon), one random stream per pixel so that the
//! image is bit-identical whatever the number of threads or the order tiles finish in.

use std::time::Instant;

use rayon::prelude::*;
use raylab_accel::Counters;
use raylab_core::{Rgb, Vec2};

use crate::sampler::PixelSampler;
use crate::Scene;

pub const TILE: u32 = 16;

/// A rendered image with what it cost.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    /// Linear RGB, row-major, row 0 at the top.
    pub pixels: Vec<Rgb>,
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

/// Renders `scene` with its settings; `progress(pixels_done)` is called as tiles finish.
pub fn render(scene: &Scene, progress: &(dyn Fn(u64) + Sync)) -> RenderOutput {
    let s = &scene.settings;
    let (w, h) = (s.width, s.height);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE)).flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE))).collect();
    let start = Instant::now();
    let done: Vec<(Vec<Rgb>, Counters, u64)> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
            let mut c = Counters::default();
            let mut bad = 0u64;
            let mut px = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            for y in y0..y1 {
                for x in x0..x1 {
                    px.push(render_pixel(scene, x, y, &mut c, &mut bad));
                }
            }
            progress(px.len() as u64);
            (px, c, bad)
        })
        .collect();
    let mut pixels = vec![Rgb::ZERO; (w * h) as usize];
    let mut counters = Counters::default();
    let mut nonfinite = 0;
    for (&(x0, y0), (px, c, bad)) in tiles.iter().zip(done) {
        let tw = (x0 + TILE).min(w) - x0;
        for (k, p) in px.into_iter().enumerate() {
            let (x, y) = (x0 + k as u32 % tw, y0 + k as u32 / tw);
            pixels[(y * w + x) as usize] = p;
        }
        counters.merge(&c);
        nonfinite += bad;
    }
    let seconds = start.elapsed().as_secs_f64();
    if s.integrator.is_heatmap() {
        crate::integrator::heatmap::colorize(&mut pixels, w, h);
    }
    RenderOutput { width: w, height: h, pixels, counters, nonfinite_samples: nonfinite, seconds }
}

/// The mean of the pixel's samples, their film positions drawn from the pixel filter.
fn render_pixel(scene: &Scene, x: u32, y: u32, c: &mut Counters, bad: &mut u64) -> Rgb {
    let s = &scene.settings;
    let inv = Vec2::new(1.0 / s.width as f32, 1.0 / s.height as f32);
    let mut sum = Rgb::ZERO;
    for i in 0..s.spp {
        let mut sampler = PixelSampler::new(s.sampler, s.spp, s.seed, x, y, i);
        let film = (Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + s.filter.offset(sampler.pixel_2d())) * inv;
        let ray = scene.camera.ray(film, sampler.get_2d());
        let l = s.integrator.radiance(scene, &ray, &mut sampler, c);
        if l.is_finite() {
            sum += l;
        } else {
            *bad += 1;
        }
    }
    sum / s.spp as f32
}
