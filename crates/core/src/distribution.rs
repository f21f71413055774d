//! Piecewise-constant distributions over [0, 1) and [0, 1)² (pbrt-v4's `PiecewiseConstant1D`
//! and `2D`): sampling by inverting a tabulated CDF, for environment maps and anything else
//! importance sampled from a table of weights.

use glam::Vec2;

/// A step function over [0, 1) with `n` equal steps, normalised into a density.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f32>,
    /// `cdf[0] = 0`, `cdf[n] = 1`, non-decreasing.
    cdf: Vec<f32>,
    /// ∫₀¹ f, the mean of the steps.
    integral: f32,
}

impl Distribution1D {
    /// From non-negative finite weights (negative or non-finite ones count as 0). All-zero
    /// weights give the uniform density, with `integral() == 0` to say so.
    pub fn new(weights: &[f32]) -> Self {
        assert!(!weights.is_empty(), "a distribution needs at least one step");
        let func: Vec<f32> = weights.iter().map(|&w| if w.is_finite() && w > 0.0 { w } else { 0.0 }).collect();
        let n = func.len();
        // f64: a 4k-wide row sums thousands of steps.
        let mut acc = 0.0f64;
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0f32);
        for &f in &func {
            acc += f as f64;
            cdf.push(acc as f32);
        }
        let integral = (acc / n as f64) as f32;
        if acc > 0.0 {
            cdf.iter_mut().for_each(|c| *c = (*c as f64 / acc) as f32);
        } else {
            cdf.iter_mut().enumerate().for_each(|(i, c)| *c = i as f32 / n as f32);
        }
        cdf[n] = 1.0;
        Self { func, cdf, integral }
    }

    pub fn len(&self) -> usize {
        self.func.len()
    }

    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// ∫₀¹ f of the (unnormalised) step function.
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// Density at step `i`.
    pub fn pdf_of_step(&self, i: usize) -> f32 {
        if self.integral > 0.0 {
            self.func[i] / self.integral
        } else {
            1.0
        }
    }

    /// Density at `x` in [0, 1).
    pub fn pdf(&self, x: f32) -> f32 {
        let i = ((x * self.len() as f32) as usize).min(self.len() - 1);
        self.pdf_of_step(i)
    }

    /// `(x, pdf, step)` for a uniform `u` in [0, 1): `x` is distributed by the density.
    pub fn sample(&self, u: f32) -> (f32, f32, usize) {
        let n = self.len();
        // The last step whose CDF start is ≤ u, skipping zero-width steps.
        let i = (self.cdf.partition_point(|&c| c <= u).max(1) - 1).min(n - 1);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 { ((u - self.cdf[i]) / width).clamp(0.0, 1.0) } else { 0.5 };
        let x = ((i as f32 + du) / n as f32).min(1.0 - f32::EPSILON);
        (x, self.pdf_of_step(i), i)
    }
}

/// A step function over [0, 1)², rows along `y`: a marginal over rows, then the row's own
/// conditional distribution along `x`.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `weights` row-major, `width × height`.
    pub fn new(weights: &[f32], width: usize, height: usize) -> Self {
        assert_eq!(weights.len(), width * height, "weights must be width × height");
        let rows: Vec<Distribution1D> = weights.chunks(width).map(Distribution1D::new).collect();
        let marginal = Distribution1D::new(&rows.iter().map(|r| r.integral()).collect::<Vec<_>>());
        Self { rows, marginal }
    }

    /// ∫∫ f over the square.
    pub fn integral(&self) -> f32 {
        self.marginal.integral()
    }

    /// A point distributed by the density and its density.
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (y, pdf_y, row) = self.marginal.sample(u.y);
        let (x, pdf_x, _) = self.rows[row].sample(u.x);
        (Vec2::new(x, y), pdf_x * pdf_y)
    }

    /// Density at `p` in [0, 1)².
    pub fn pdf(&self, p: Vec2) -> f32 {
        let row = ((p.y * self.rows.len() as f32) as usize).min(self.rows.len() - 1);
        self.marginal.pdf_of_step(row) * self.rows[row].pdf(p.x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_dimension_hits_steps_in_proportion_and_reports_their_density() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0]);
        assert!((d.integral() - 4.0 / 3.0).abs() < 1e-6);
        // u below 1/4 lands in step 0, above in step 2; the empty step is never chosen.
        let (x, pdf, i) = d.sample(0.125);
        assert_eq!(i, 0);
        assert!((x - 1.0 / 6.0).abs() < 1e-6, "{x}");
        assert!((pdf - 0.75).abs() < 1e-6);
        let (x, pdf, i) = d.sample(0.25);
        assert_eq!(i, 2);
        assert!((x - 2.0 / 3.0).abs() < 1e-6, "{x}");
        assert!((pdf - 2.25).abs() < 1e-6);
        assert_eq!(d.pdf(0.5), 0.0);
        assert_eq!(d.sample(0.999_999).2, 2);
    }

    #[test]
    fn all_zero_weights_fall_back_to_uniform() {
        let d = Distribution1D::new(&[0.0, 0.0]);
        assert_eq!(d.integral(), 0.0);
        assert_eq!(d.pdf(0.3), 1.0);
        let (x, _, i) = d.sample(0.75);
        assert_eq!(i, 1);
        assert!((x - 0.75).abs() < 1e-6);
    }

    #[test]
    fn two_dimensions_sample_matches_pdf_and_integrates_to_one() {
        let w = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let d = Distribution2D::new(&w, 3, 2);
        assert!((d.integral() - 2.5).abs() < 1e-6);
        let mut rng = crate::Pcg32::new(7, 1);
        let mut counts = [0usize; 6];
        let n = 60_000;
        for _ in 0..n {
            let (p, pdf) = d.sample(Vec2::new(rng.next_f32(), rng.next_f32()));
            assert!((pdf - d.pdf(p)).abs() < 1e-5, "{pdf} vs {}", d.pdf(p));
            counts[(p.y * 2.0) as usize * 3 + (p.x * 3.0) as usize] += 1;
        }
        // Each cell is hit in proportion to its weight (15 in all).
        for (k, &c) in counts.iter().enumerate() {
            let expected = n as f32 * w[k] / 15.0;
            assert!((c as f32 - expected).abs() <= 4.0 * expected.sqrt() + 1.0, "cell {k}: {c} vs {expected}");
        }
        // The density integrates to 1: mean of pdf at cell centres × area.
        let total: f32 = (0..6).map(|k| d.pdf(Vec2::new((k % 3) as f32 / 3.0 + 0.1, (k / 3) as f32 / 2.0 + 0.1)) / 6.0).sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
    }
}
