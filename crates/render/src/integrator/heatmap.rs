//! Traversal-cost heat maps: per pixel, the mean number of acceleration-structure nodes
//! visited (or primitive tests made) by its camera rays, drawn in false colour with a
//! legend, so a user sees *where* a structure pays.

use raylab_accel::Counters;
use raylab_core::{Ray, Rgb, Vec3};

use crate::Scene;

/// What a heat map counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeatMetric {
    NodesVisited,
    PrimTests,
}

/// The cost of the camera ray alone, stored in every channel (colourised after the render).
pub(super) fn cost(scene: &Scene, ray: &Ray, metric: HeatMetric, c: &mut Counters) -> Rgb {
    let before = *c;
    scene.intersect(ray, c);
    let n = match metric {
        HeatMetric::NodesVisited => c.nodes_visited - before.nodes_visited,
        HeatMetric::PrimTests => c.prim_tests - before.prim_tests,
    };
    Rgb::splat(n as f32)
}

/// "Turbo"-like ramp (Mikhailov 2019, polynomial fit): dark blue → green → yellow → dark red.
pub fn ramp(x: f32) -> Rgb {
    let x = x.clamp(0.0, 1.0);
    let r = 0.13572138 + x * (4.6153926 + x * (-42.66032258 + x * (132.13108234 + x * (-152.94239396 + x * 59.28637943))));
    let g = 0.09140261 + x * (2.19418839 + x * (4.84296658 + x * (-14.18503333 + x * (4.27729857 + x * 2.82956604))));
    let b = 0.1066733 + x * (12.64194608 + x * (-60.58204836 + x * (110.36276771 + x * (-89.90310912 + x * 27.34824973))));
    // The fit is in display (sRGB) space; images are linear, so undo the encoding.
    Vec3::new(r, g, b).clamp(Vec3::ZERO, Vec3::ONE).map(raylab_core::color::srgb_to_linear)
}

/// Replaces raw costs by colours scaled to `[0, max]` and draws a legend along the bottom
/// rows: the ramp, and `0` and `max` as digits. Returns the maximum.
pub fn colorize(pixels: &mut [Rgb], width: u32, height: u32) -> f32 {
    let max = pixels.iter().map(|p| p.x).fold(0.0f32, f32::max).max(1.0);
    for p in pixels.iter_mut() {
        *p = ramp(p.x / max);
    }
    let bar_h = (height / 24).clamp(4, 24);
    if height < 3 * bar_h || width < 40 {
        return max;
    }
    let top = height - bar_h;
    for y in top..height {
        for x in 0..width {
            pixels[(y * width + x) as usize] = ramp(x as f32 / (width - 1) as f32);
        }
    }
    let scale = ((bar_h - 2) / 5).max(1);
    let label_y = top.saturating_sub(5 * scale + 2);
    draw_number(pixels, width, 2, label_y, scale, 0);
    let text = (max.round() as u64).to_string();
    let text_w = text.len() as u32 * 4 * scale;
    draw_number(pixels, width, width.saturating_sub(text_w + 2), label_y, scale, max.round() as u64);
    max
}

/// 3×5 pixel digits, one `u16` of 15 bits per digit, rows top to bottom.
const DIGITS: [u16; 10] = [0x7B6F, 0x2C97, 0x73E7, 0x73CF, 0x5BC9, 0x79CF, 0x79EF, 0x7249, 0x7BEF, 0x7BCF];

fn draw_number(pixels: &mut [Rgb], width: u32, x0: u32, y0: u32, scale: u32, n: u64) {
    let height = pixels.len() as u32 / width;
    for (k, ch) in n.to_string().bytes().enumerate() {
        let bits = DIGITS[(ch - b'0') as usize];
        for row in 0..5 {
            for col in 0..3 {
                let on = bits >> (14 - (row * 3 + col)) & 1 == 1;
                for dy in 0..scale {
                    for dx in 0..scale {
                        let x = x0 + (k as u32 * 4 + col) * scale + dx;
                        let y = y0 + row * scale + dy;
                        if x < width && y < height {
                            pixels[(y * width + x) as usize] = if on { Rgb::ONE } else { Rgb::ZERO };
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_runs_from_blue_to_red() {
        let lo = ramp(0.15);
        let hi = ramp(0.95);
        assert!(lo.z > lo.x && hi.x > hi.z);
        assert!(ramp(0.5).y > 0.5);
    }

    #[test]
    fn colorize_scales_to_the_maximum_and_draws_a_legend() {
        let (w, h) = (64u32, 64u32);
        let mut px: Vec<Rgb> = (0..w * h).map(|i| Rgb::splat((i % w) as f32)).collect();
        let max = colorize(&mut px, w, h);
        assert_eq!(max, 63.0);
        // Top-left is cost 0 -> the ramp's start; bottom row is the legend ramp.
        assert_eq!(px[0], ramp(0.0));
        assert_eq!(px[((h - 1) * w + w - 1) as usize], ramp(1.0));
    }
}
