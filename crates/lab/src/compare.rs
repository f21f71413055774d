//! Error metrics between a rendered image `a` and a reference `b`, for measuring how a
//! renderer converges, and a false-colour picture of where they differ.
//!
//! Images are linear RGB, row-major, top row first. Over the compared pixels:
//! - **MSE**: the squared difference per channel, averaged over channels and pixels;
//!   **RMSE** is its square root.
//! - **Relative MSE**: the mean over pixels and channels of `(a - b)² / (b² + 0.01)`, with `b`
//!   the reference — the convention of Rousselle et al. and the denoising literature, which
//!   weighs errors in dark regions as much as in bright ones; the `0.01` keeps black pixels
//!   from dividing by zero.
//! - **PSNR**: `10 log10(1 / MSE)` decibels against a peak of 1.0 (infinite when MSE is 0).
//! - **max |diff|**: the largest absolute difference in any channel.
//!
//! Fireflies and directly visible lights can dominate every mean; `exclude_bright = Some(T)`
//! leaves out the pixels whose *reference* luminance exceeds `T` (the reference, so that both
//! images of a pair lose the same pixels whichever one is noisy).

use raylab_core::color::luminance;
use raylab_core::Rgb;
use raylab_render::integrator::heatmap::ramp;

/// The metrics of [`compare`]; see the module documentation for their definitions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageDiff {
    pub mse: f64,
    pub rmse: f64,
    pub rel_mse: f64,
    pub max_abs: f64,
    pub psnr_db: f64,
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels left out by `exclude_bright`.
    pub excluded: usize,
}

/// The error of `a` against the reference `b`, both `width` pixels wide.
///
/// Fails with `pixel (x, y) is not finite` at the first NaN or infinity in either image
/// (excluded pixels included: such a value is a bug to report, not a firefly), and when every
/// pixel is excluded. Panics if the lengths differ: callers check the sizes first.
pub fn compare(a: &[Rgb], b: &[Rgb], width: u32, exclude_bright: Option<f32>) -> Result<ImageDiff, String> {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    let (mut sq, mut rel, mut max_abs) = (0.0f64, 0.0f64, 0.0f64);
    let (mut pixels, mut excluded) = (0, 0);
    for (i, (p, q)) in a.iter().zip(b).enumerate() {
        if !p.is_finite() || !q.is_finite() {
            let w = width as usize;
            return Err(format!("pixel ({}, {}) is not finite", i % w, i / w));
        }
        if exclude_bright.is_some_and(|t| luminance(*q) > t) {
            excluded += 1;
            continue;
        }
        pixels += 1;
        for (x, y) in p.to_array().into_iter().zip(q.to_array()) {
            let (x, y) = (x as f64, y as f64);
            let d2 = (x - y) * (x - y);
            sq += d2;
            rel += d2 / (y * y + 1e-2);
            max_abs = max_abs.max((x - y).abs());
        }
    }
    if pixels == 0 && excluded > 0 {
        return Err(format!("all {excluded} pixels are excluded as brighter than {} in the reference", exclude_bright.unwrap()));
    }
    let samples = 3.0 * pixels.max(1) as f64;
    let mse = sq / samples;
    Ok(ImageDiff { mse, rmse: mse.sqrt(), rel_mse: rel / samples, max_abs, psnr_db: -10.0 * mse.log10(), pixels, excluded })
}

/// A false-colour image of the absolute luminance difference per pixel, through the heat-map
/// ramp, with `scale` (or, by default, the 99th percentile of the differences, so that a few
/// fireflies do not turn everything else dark blue) mapped to the top of the ramp. Returns the
/// image and the scale used; a scale of 0 (identical images) maps every pixel to the bottom.
pub fn false_colour(a: &[Rgb], b: &[Rgb], scale: Option<f32>) -> (Vec<Rgb>, f32) {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    let diffs: Vec<f32> = a.iter().zip(b).map(|(p, q)| (luminance(*p) - luminance(*q)).abs()).collect();
    let scale = scale.unwrap_or_else(|| percentile(&diffs, 0.99));
    let colours = diffs.iter().map(|&d| ramp(if scale > 0.0 { d / scale } else { 0.0 })).collect();
    (colours, scale)
}

/// The nearest-rank `p`-quantile: the smallest value with at least a fraction `p` of the
/// values at or below it (0 for no values).
fn percentile(values: &[f32], p: f64) -> f32 {
    if values.is_empty() {
        return 0.0;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f32::total_cmp);
    let rank = (p * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(v: f32, n: usize) -> Vec<Rgb> {
        vec![Rgb::splat(v); n]
    }

    #[test]
    fn metrics_of_a_constant_offset() {
        let d = compare(&grey(0.5, 6), &grey(0.25, 6), 3, None).unwrap();
        assert_eq!(d.mse, 0.0625);
        assert_eq!(d.rmse, 0.25);
        assert_eq!(d.max_abs, 0.25);
        assert!((d.rel_mse - 0.0625 / (0.0625 + 1e-2)).abs() < 1e-12);
        assert!((d.psnr_db - 10.0 * 16f64.log10()).abs() < 1e-12);
        assert_eq!((d.pixels, d.excluded), (6, 0));
    }

    #[test]
    fn errors_are_averaged_over_channels_and_pixels() {
        // One channel of one pixel of two differs by 1: 1 / (3 × 2).
        let a = [Rgb::new(1.0, 0.0, 0.0), Rgb::ZERO];
        let d = compare(&a, &[Rgb::ZERO; 2], 2, None).unwrap();
        assert_eq!(d.mse, 1.0 / 6.0);
        assert!((d.rel_mse - 1.0 / 1e-2 / 6.0).abs() < 1e-12);
        assert_eq!(d.max_abs, 1.0);
    }

    #[test]
    fn identical_images_have_infinite_psnr() {
        let d = compare(&grey(0.3, 4), &grey(0.3, 4), 2, None).unwrap();
        assert_eq!((d.mse, d.rel_mse, d.max_abs), (0.0, 0.0, 0.0));
        assert_eq!(d.psnr_db, f64::INFINITY);
    }

    #[test]
    fn bright_reference_pixels_are_excluded() {
        let mut b = grey(0.25, 4);
        b[1] = Rgb::splat(10.0); // a visible light in the reference
        let mut a = grey(0.25, 4);
        a[2] = Rgb::splat(10.0); // a firefly in the render: still counted
        let d = compare(&a, &b, 2, Some(1.0)).unwrap();
        assert_eq!((d.pixels, d.excluded), (3, 1));
        assert_eq!(d.mse, 9.75f64 * 9.75 / 3.0);
        assert!(compare(&b, &b, 2, Some(0.1)).unwrap_err().starts_with("all 4 pixels are excluded"));
    }

    #[test]
    fn non_finite_pixels_are_reported_by_position() {
        let mut b = grey(0.0, 6);
        b[4] = Rgb::new(0.0, f32::NAN, 0.0);
        assert_eq!(compare(&grey(0.0, 6), &b, 3, None).unwrap_err(), "pixel (1, 1) is not finite");
        assert_eq!(compare(&b, &grey(0.0, 6), 2, Some(1.0)).unwrap_err(), "pixel (0, 2) is not finite");
    }

    #[test]
    fn percentile_is_nearest_rank() {
        let v: Vec<f32> = (1..=100).map(|k| k as f32).rev().collect();
        assert_eq!(percentile(&v, 0.99), 99.0);
        assert_eq!(percentile(&v, 1.0), 100.0);
        assert_eq!(percentile(&v, 0.0), 1.0);
        assert_eq!(percentile(&[], 0.99), 0.0);
    }

    #[test]
    fn false_colour_scales_by_the_99th_percentile_ignoring_a_firefly() {
        // Differences 1..=99 and one firefly of 1000: the scale is 99, not 1000.
        let mut a: Vec<Rgb> = (1..=99).map(|k| Rgb::splat(k as f32)).collect();
        a.push(Rgb::splat(1000.0));
        let b = grey(0.0, 100);
        let (img, scale) = false_colour(&a, &b, None);
        assert!((scale - 99.0).abs() < 1e-3, "{scale}");
        assert_eq!(img[98], ramp(1.0));
        assert_eq!(img[99], ramp(1.0)); // the firefly saturates
        assert!((img[48] - ramp(49.0 / 99.0)).abs().max_element() < 1e-3);
        // An explicit scale is used as given.
        let (img, scale) = false_colour(&a, &b, Some(198.0));
        assert_eq!(scale, 198.0);
        assert!((img[98] - ramp(0.5)).abs().max_element() < 1e-3);
    }

    #[test]
    fn false_colour_of_identical_images_is_the_bottom_of_the_ramp() {
        let (img, scale) = false_colour(&grey(0.5, 4), &grey(0.5, 4), None);
        assert_eq!(scale, 0.0);
        assert!(img.iter().all(|&c| c == ramp(0.0)));
    }
}
