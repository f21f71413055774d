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
/// The coefficients are the published fit's, digit for digit.
#[allow(clippy::excessive_precision)]
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
    use raylab_accel::{AccelKind, BuildOptions};
    use raylab_core::Transform;

    use crate::{Camera, IntegratorKind, MaterialId, PixelSampler, RenderSettings, SamplerKind, Sphere, TriangleMesh};

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

    /// Mikhailov's "Turbo" polynomial (his published fit's coefficients, lowest power first),
    /// summed term by term in f64, clamped to [0, 1] and decoded from sRGB with the
    /// IEC 61966-2-1 formula written out here.
    fn turbo_reference(x: f64) -> [f64; 3] {
        const R: [f64; 6] = [0.13572138, 4.61539260, -42.66032258, 132.13108234, -152.94239396, 59.28637943];
        const G: [f64; 6] = [0.09140261, 2.19418839, 4.84296658, -14.18503333, 4.27729857, 2.82956604];
        const B: [f64; 6] = [0.10667330, 12.64194608, -60.58204836, 110.36276771, -89.90310912, 27.34824973];
        let x = x.clamp(0.0, 1.0);
        let decode = |c: f64| if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
        [R, G, B].map(|k| decode((0..6).map(|i| k[i] * x.powi(i as i32)).sum::<f64>().clamp(0.0, 1.0)))
    }

    #[test]
    fn ramp_is_mikhailovs_turbo_polynomial_decoded_from_srgb() {
        // The f32 Horner form loses up to ~1.3e-5 to cancellation (terms of ±150 summing to ~1).
        for x in [-0.5, 0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0, 2.0] {
            let want = turbo_reference(x);
            let got = ramp(x as f32);
            for (c, (g, w)) in [got.x, got.y, got.z].into_iter().zip(want).enumerate() {
                assert!((g as f64 - w).abs() < 1e-4, "ramp({x}) channel {c}: {g} (expected {w})");
            }
        }
        // By hand at the ends. x = 0: the constant terms, sRGB (0.13572138, 0.09140261,
        // 0.1066733), each above 0.04045, so linear ((c + 0.055) / 1.055)^2.4 =
        // (0.0165, 0.0087, 0.0111).
        let lin = |c: f64| ((c + 0.055) / 1.055).powf(2.4);
        let at0 = ramp(0.0);
        for (g, s) in [(at0.x, 0.13572138), (at0.y, 0.09140261), (at0.z, 0.1066733)] {
            assert!((g as f64 - lin(s)).abs() < 1e-6, "{at0}");
        }
        assert!((at0.x - 0.0165).abs() < 1e-4 && (at0.y - 0.0087).abs() < 1e-4 && (at0.z - 0.0111).abs() < 1e-4, "{at0}");
        // x = 1: the sums of the coefficients, sRGB r = 0.56585921, g = 0.05038886 and
        // b = −0.02552066, clamped to 0: linear (0.2801, 0.0040, 0). Below 0 the ramp stays
        // at 0, above 1 at 1.
        let at1 = ramp(1.0);
        assert!((at1.x as f64 - lin(0.56585921)).abs() < 1e-4 && (at1.y as f64 - lin(0.05038886)).abs() < 1e-4, "{at1}");
        assert!((at1.x - 0.2801).abs() < 1e-4 && (at1.y - 0.0040).abs() < 1e-4, "{at1}");
        assert_eq!(at1.z, 0.0);
        assert_eq!(ramp(-3.0), at0);
        assert_eq!(ramp(7.0), at1);
        // x = 0.75: r = 1.02064 in sRGB, clamped to 1 (linear 1).
        assert!((ramp(0.75).x - 1.0).abs() < 1e-6);
    }

    /// In this order, each its own box under `AccelKind::Aabb`: a sphere of radius ½ at the
    /// origin (1 primitive), the cube [−1, 1]³ around it (12 triangles), spheres of radius ½ at
    /// (0, −3, 0) and at (3, 0, 0): 15 primitives.
    fn objects_scene(accel: AccelKind) -> Scene {
        let camera = Camera::new(Vec3::new(0.0, 5.0, 3.0), Vec3::ZERO, Vec3::Y, 45.0, 1.0, 0.0, None).unwrap();
        let settings = RenderSettings { width: 1, height: 1, spp: 1, accel, ..Default::default() };
        let mut scene = Scene::new(camera, settings);
        let m = MaterialId(0);
        let sphere = |center: Vec3| Sphere { center, radius: 0.5, to_world: Transform::IDENTITY, material: m, emission: Rgb::ZERO };
        scene.geometry.add_sphere(sphere(Vec3::ZERO));
        let corner = |i: u32| Vec3::new(if i & 1 == 0 { -1.0 } else { 1.0 }, if i & 2 == 0 { -1.0 } else { 1.0 }, if i & 4 == 0 { -1.0 } else { 1.0 });
        let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
        let indices = faces.iter().flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]).collect();
        scene.geometry.add_mesh(TriangleMesh { name: "cube".into(), positions: (0..8).map(corner).collect(), indices, material: m, ..Default::default() });
        scene.geometry.add_sphere(sphere(Vec3::new(0.0, -3.0, 0.0)));
        scene.geometry.add_sphere(sphere(Vec3::new(3.0, 0.0, 0.0)));
        scene.build_accel(&BuildOptions::default());
        scene
    }

    #[test]
    fn heatmap_cost_is_the_camera_rays_own_nodes_and_tests() {
        // Straight down from (0.25, 5, 0.1) (off the top face's diagonal x = z), and straight up.
        let down = Ray::new(Vec3::new(0.25, 5.0, 0.1), Vec3::new(0.0, -1.0, 0.0));
        let up = Ray::new(Vec3::new(0.25, 5.0, 0.1), Vec3::new(0.0, 1.0, 0.0));
        // Per-object boxes, walked in order, each box tested within the ray's current interval:
        // the first sphere's box is entered at t = 4.5 (1 test; the sphere is hit at
        // t = 5 − √(0.25 − 0.25² − 0.1²) ≈ 4.58), the cube's at t = 4 < 4.58 (12 tests; its top
        // hit at t = 4), the third sphere's box would be entered at t = 7.5 > 4 (pruned), the
        // fourth's x range [2.5, 3.5] misses x = 0.25: 2 nodes, 13 tests. Going up, every box is
        // below the origin: 0 and 0. Brute force: no nodes, every primitive tested, 15.
        let cases = [(AccelKind::Aabb, down, 2.0, 13.0), (AccelKind::Aabb, up, 0.0, 0.0), (AccelKind::None, down, 0.0, 15.0), (AccelKind::None, up, 0.0, 15.0)];
        // Counters already holding earlier rays' counts: the cost is the difference.
        let seeded = Counters { rays: 3, nodes_visited: 1000, prim_tests: 500, object_tests: 7 };
        for (accel, ray, nodes, tests) in cases {
            let scene = objects_scene(accel);
            let what = format!("{accel:?}, direction {}", ray.dir);
            let mut c = seeded;
            assert_eq!(cost(&scene, &ray, HeatMetric::NodesVisited, &mut c), Rgb::splat(nodes), "{what}");
            // The counters go on accumulating: the render's statistics still see the ray.
            assert_eq!((c.rays, c.nodes_visited, c.prim_tests), (4, 1000 + nodes as u64, 500 + tests as u64), "{what}");
            assert_eq!(cost(&scene, &ray, HeatMetric::PrimTests, &mut c), Rgb::splat(tests), "{what}");
            assert_eq!((c.rays, c.nodes_visited, c.prim_tests), (5, 1000 + 2 * nodes as u64, 500 + 2 * tests as u64), "{what}");
            // The same through the integrators: `heatmap` counts nodes, `heatmap-tests` tests.
            for (kind, want) in [(IntegratorKind::Heatmap, nodes), (IntegratorKind::HeatmapTests, tests)] {
                let mut sampler = PixelSampler::new(SamplerKind::Random, 1, 11, 0, 0, 0);
                let mut c = seeded;
                assert_eq!(kind.radiance(&scene, &ray, &mut sampler, &mut c), Rgb::splat(want), "{what}, {kind}");
            }
        }
    }

    #[test]
    fn colorize_without_a_legend_only_scales() {
        // Too small for a legend (width < 40): each cost c becomes ramp(c / max).
        let mut px = vec![Rgb::splat(0.0), Rgb::splat(1.0), Rgb::splat(2.0), Rgb::splat(4.0)];
        assert_eq!(colorize(&mut px, 4, 1), 4.0);
        assert_eq!(px, [ramp(0.0), ramp(0.25), ramp(0.5), ramp(1.0)]);
        // A maximum below 1 counts as 1 (a scene the rays all miss stays dark blue).
        let mut px = vec![Rgb::splat(0.5), Rgb::splat(0.25), Rgb::ZERO, Rgb::splat(0.75)];
        assert_eq!(colorize(&mut px, 2, 2), 1.0);
        assert_eq!(px, [ramp(0.5), ramp(0.25), ramp(0.0), ramp(0.75)]);
    }

    /// The 3 × 5 digits as the legend must draw them, `#` on (white), `.` off (black).
    const GLYPHS: [[&str; 5]; 10] = [
        ["###", "#.#", "#.#", "#.#", "###"],
        [".#.", "##.", ".#.", ".#.", "###"],
        ["###", "..#", "###", "#..", "###"],
        ["###", "..#", "###", "..#", "###"],
        ["#.#", "#.#", "###", "..#", "..#"],
        ["###", "#..", "###", "..#", "###"],
        ["###", "#..", "###", "#.#", "###"],
        ["###", "..#", "..#", "..#", "..#"],
        ["###", "#.#", "###", "#.#", "###"],
        ["###", "#.#", "###", "..#", "###"],
    ];

    /// What `colorize` must make of costs `v` (row by row) whose maximum is `max`, with the
    /// legend's sizes worked out by the caller: every pixel's cost on the ramp; the bottom
    /// `bar_h` rows the ramp from 0 at column 0 to 1 at the last column; from row `label_y`,
    /// in dots of `scale` × `scale` pixels, "0" from column 2 and then `label` from column
    /// `label_x`, each digit 4 dots wide (3, and a gap keeping what is under it), cut at the
    /// right edge.
    #[allow(clippy::too_many_arguments)]
    fn expected(v: &[f32], width: u32, max: f32, bar_h: u32, scale: u32, label_y: u32, label: &str, label_x: u32) -> Vec<Rgb> {
        let height = v.len() as u32 / width;
        let mut want: Vec<Rgb> = v.iter().map(|&c| ramp(c / max)).collect();
        for y in height - bar_h..height {
            for x in 0..width {
                want[(y * width + x) as usize] = ramp(x as f32 / (width - 1) as f32);
            }
        }
        for (text, x0) in [("0", 2), (label, label_x)] {
            for (k, ch) in text.chars().enumerate() {
                for (row, line) in GLYPHS[ch.to_digit(10).unwrap() as usize].iter().enumerate() {
                    for (col, dot) in line.chars().enumerate() {
                        let (dot_x, dot_y) = (x0 + (4 * k as u32 + col as u32) * scale, label_y + row as u32 * scale);
                        for y in dot_y..dot_y + scale {
                            for x in (dot_x..dot_x + scale).filter(|&x| x < width) {
                                want[(y * width + x) as usize] = if dot == '#' { Rgb::ONE } else { Rgb::ZERO };
                            }
                        }
                    }
                }
            }
        }
        want
    }

    fn assert_image(got: &[Rgb], want: &[Rgb], width: usize, what: &str) {
        assert_eq!(got.len(), want.len());
        for (i, (g, w)) in got.iter().zip(want).enumerate() {
            assert_eq!(g, w, "{what}: pixel ({}, {})", i % width, i / width);
        }
    }

    #[test]
    fn colorize_draws_the_legend_from_40_by_12_pixels() {
        // 40 × 12: bar height clamp(12 / 24 = 0, 4, 24) = 4, and 12 ≥ 3·4, 40 ≥ 40: a legend.
        // Bar rows 8..12; dots max((4 − 2) / 5 = 0, 1) = 1 pixel; labels from row
        // 8 − (5·1 + 2) = 1; costs 0..7, so "7", 4 dots wide, from column 40 − 4 − 2 = 34.
        let costs = |w: u32, h: u32| (0..w * h).map(|i| (i % 8) as f32).collect::<Vec<f32>>();
        let v = costs(40, 12);
        let mut px: Vec<Rgb> = v.iter().map(|&c| Rgb::splat(c)).collect();
        assert_eq!(colorize(&mut px, 40, 12), 7.0);
        assert_image(&px, &expected(&v, 40, 7.0, 4, 1, 1, "7", 34), 40, "40 × 12");
        // One column or one row fewer: no legend (40 × 11: bar height 4, 11 < 12).
        for (w, h) in [(39, 12), (40, 11)] {
            let v = costs(w, h);
            let mut px: Vec<Rgb> = v.iter().map(|&c| Rgb::splat(c)).collect();
            assert_eq!(colorize(&mut px, w, h), 7.0);
            let want: Vec<Rgb> = v.iter().map(|&c| ramp(c / 7.0)).collect();
            assert_image(&px, &want, w as usize, &format!("{w} × {h}"));
        }
    }

    #[test]
    fn colorize_labels_the_rounded_maximum_in_scaled_digits() {
        // 40 × 312: bar height 312 / 24 = 13 (rows 299..312), dots (13 − 2) / 5 = 2 pixels,
        // labels from row 299 − (5·2 + 2) = 287. Costs 0.75, 1.25, ..., up to 211·0.5 + 0.75 =
        // 106.25: scaled by 106.25, labelled "106", 3·4·2 = 24 pixels wide, from 40 − 24 − 2 = 14.
        let v: Vec<f32> = (0..40 * 312).map(|i| (i % 212) as f32 * 0.5 + 0.75).collect();
        let mut px: Vec<Rgb> = v.iter().map(|&c| Rgb::splat(c)).collect();
        assert_eq!(colorize(&mut px, 40, 312), 106.25);
        assert_image(&px, &expected(&v, 40, 106.25, 13, 2, 287, "106", 14), 40, "40 × 312");
    }

    #[test]
    fn colorize_cuts_a_label_too_wide_for_the_image() {
        // 40 × 528: bar height 528 / 24 = 22 (rows 506..528), dots (22 − 2) / 5 = 4 pixels,
        // labels from row 506 − (5·4 + 2) = 484. The maximum 12345 is 5·4·4 = 80 pixels wide,
        // more than 40 − 2: it starts at column 0 (over the "0") and is cut at column 39.
        let v: Vec<f32> = (0..40 * 528).map(|i| if i == 0 { 12345.0 } else { (i % 50) as f32 }).collect();
        let mut px: Vec<Rgb> = v.iter().map(|&c| Rgb::splat(c)).collect();
        assert_eq!(colorize(&mut px, 40, 528), 12345.0);
        assert_image(&px, &expected(&v, 40, 12345.0, 22, 4, 484, "12345", 0), 40, "40 × 528");
    }

    #[test]
    fn colorize_labels_an_image_of_two_megapixels() {
        // 2048 × 1152, the size of a real render (the pixel count times the width, 4.8·10⁹,
        // is past u32): bar height min(1152 / 24 = 48, 24) = 24 (rows 1128..1152), dots
        // (24 − 2) / 5 = 4 pixels, labels from row 1128 − (5·4 + 2) = 1106; costs 0..999,
        // "999", 3·4·4 = 48 pixels wide, from column 2048 − 48 − 2 = 1998.
        let (w, h) = (2048u32, 1152u32);
        let v: Vec<f32> = (0..w * h).map(|i| (i % 1000) as f32).collect();
        let mut px: Vec<Rgb> = v.iter().map(|&c| Rgb::splat(c)).collect();
        assert_eq!(colorize(&mut px, w, h), 999.0);
        assert_image(&px, &expected(&v, w, 999.0, 24, 4, 1106, "999", 1998), w as usize, "2048 × 1152");
    }
}
