//! Pixel reconstruction filters, applied by filter importance sampling (pbrt-v4 §8.8): each
//! sample's film offset is drawn from the filter itself, so every sample has weight 1 and a
//! pixel is the plain mean of its samples. The box filter is the pixel's square.

use std::sync::OnceLock;

use raylab_core::Vec2;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PixelFilter {
    /// Uniform over the pixel's square (radius ½).
    #[default]
    Box,
    /// Separable tent of radius 1 pixel: `(1 - |x|)(1 - |y|)`.
    Tent,
    /// Separable Gaussian, σ = 0.5 pixel, truncated at radius 1.5 pixels.
    Gaussian,
}

raylab_core::named_enum!(PixelFilter, "pixel filter", {
    Box => "box",
    Tent => "tent",
    Gaussian => "gaussian",
});

const GAUSSIAN_SIGMA: f32 = 0.5;
const GAUSSIAN_RADIUS: f32 = 1.5;

impl PixelFilter {
    /// The film offset from the pixel's centre for a uniform sample `u` in `[0,1)²`.
    pub fn offset(self, u: Vec2) -> Vec2 {
        match self {
            PixelFilter::Box => u - Vec2::splat(0.5),
            PixelFilter::Tent => Vec2::new(tent(u.x), tent(u.y)),
            PixelFilter::Gaussian => Vec2::new(gaussian(u.x), gaussian(u.y)),
        }
    }
}

/// Inverse CDF of the tent `1 - |x|` on [-1, 1].
fn tent(u: f32) -> f32 {
    if u < 0.5 { (2.0 * u).sqrt() - 1.0 } else { 1.0 - (2.0 - 2.0 * u).max(0.0).sqrt() }
}

/// Inverse CDF of the truncated Gaussian, by a table of its CDF (no closed form).
fn gaussian(u: f32) -> f32 {
    const N: usize = 1024;
    static CDF: OnceLock<Vec<f32>> = OnceLock::new();
    let cdf = CDF.get_or_init(|| {
        let f = |x: f32| (-x * x / (2.0 * GAUSSIAN_SIGMA * GAUSSIAN_SIGMA)).exp();
        let dx = 2.0 * GAUSSIAN_RADIUS / N as f32;
        let mut acc = vec![0.0f32; N + 1];
        for i in 0..N {
            let x = -GAUSSIAN_RADIUS + (i as f32 + 0.5) * dx;
            acc[i + 1] = acc[i] + f(x) * dx;
        }
        let total = acc[N];
        acc.iter().map(|a| a / total).collect()
    });
    // The bin holding u, then linear inside it (the density is piecewise constant).
    let i = cdf.partition_point(|&c| c <= u).clamp(1, N) - 1;
    let t = (u - cdf[i]) / (cdf[i + 1] - cdf[i]).max(f32::MIN_POSITIVE);
    -GAUSSIAN_RADIUS + (i as f32 + t.clamp(0.0, 1.0)) * (2.0 * GAUSSIAN_RADIUS / N as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean and variance of the offsets along x over a fine grid of `u`.
    fn moments(f: PixelFilter) -> (f64, f64, f32) {
        let n = 100_000;
        let xs: Vec<f32> = (0..n).map(|i| f.offset(Vec2::new((i as f32 + 0.5) / n as f32, 0.5)).x).collect();
        let mean = xs.iter().map(|&x| x as f64).sum::<f64>() / n as f64;
        let var = xs.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / n as f64;
        (mean, var, xs.iter().fold(0.0f32, |m, &x| m.max(x.abs())))
    }

    #[test]
    fn offsets_at_hand_worked_points() {
        // Box: the offset is u − ½ on each axis.
        assert_eq!(PixelFilter::Box.offset(Vec2::new(0.25, 0.9)), Vec2::new(-0.25, 0.9 - 0.5));
        // Tent 1 − |x| on [−1, 1]: CDF (1 + x)²/2 left of 0, 1 − (1 − x)²/2 right of it, so
        // u = 0.02 → −0.8, 0.125 → −0.5, ½ → 0, 0.875 → 0.5, 0.98 → 0.8; each axis on its own.
        for (u, x) in [(0.02f32, -0.8f32), (0.125, -0.5), (0.5, 0.0), (0.875, 0.5), (0.98, 0.8), (0.0, -1.0)] {
            let o = PixelFilter::Tent.offset(Vec2::new(u, 0.875));
            assert!((o.x - x).abs() < 1e-6 && (o.y - 0.5).abs() < 1e-6, "tent({u}) = {o}");
        }
        // Gaussian σ = ½ truncated at ±1.5 = ±3σ: the CDF at x is (Φ(x/σ) − Φ(−3)) / (Φ(3) − Φ(−3)),
        // with Φ(−3) = 0.0013498980, Φ(−2) = 0.0227501319, Φ(1) = 0.8413447461 (Abramowitz &
        // Stegun 26.2): the offsets −1 (2σ), 0, ½ (1σ) and the ends.
        let (lo, hi) = (0.001_349_898_0f64, 0.998_650_102_0f64);
        let cdf = |phi: f64| ((phi - lo) / (hi - lo)) as f32;
        for (u, x) in [(cdf(0.022_750_131_9), -1.0f32), (0.5, 0.0), (cdf(0.841_344_746_1), 0.5), (0.0, -1.5)] {
            let o = PixelFilter::Gaussian.offset(Vec2::new(u, 1.0 - u));
            assert!((o.x - x).abs() < 2e-4 && (o.y + x).abs() < 2e-4, "gaussian({u}) = {o}, expected ({x}, {})", -x);
        }
        let end = PixelFilter::Gaussian.offset(Vec2::splat(1.0 - f32::EPSILON / 2.0)).x;
        assert!((end - 1.5).abs() < 1e-3, "{end}");
    }

    #[test]
    fn offsets_follow_the_filters() {
        // Box: uniform on [-½, ½], variance 1/12. Tent of radius 1: variance 1/6.
        let (m, v, r) = moments(PixelFilter::Box);
        assert!(m.abs() < 1e-6 && (v - 1.0 / 12.0).abs() < 1e-4 && r <= 0.5, "{m} {v} {r}");
        let (m, v, r) = moments(PixelFilter::Tent);
        assert!(m.abs() < 1e-6 && (v - 1.0 / 6.0).abs() < 1e-4 && r <= 1.0, "{m} {v} {r}");
        // Gaussian σ = ½ truncated at 3σ: variance σ²(1 - 6φ(3)/(2Φ(3) - 1)) = 0.24324.
        let (m, v, r) = moments(PixelFilter::Gaussian);
        assert!(m.abs() < 1e-5 && (v - 0.243_24).abs() < 1e-3 && r <= 1.5, "{m} {v} {r}");
        assert_eq!("tent".parse::<PixelFilter>().unwrap(), PixelFilter::Tent);
        assert_eq!("mitchell".parse::<PixelFilter>().unwrap_err(), "unknown pixel filter `mitchell` (valid: box, tent, gaussian)");
    }
}
