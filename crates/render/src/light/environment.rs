//! The environment light: radiance from infinitely far away, read from an equirectangular
//! image (the mapping of [`equirect_uv`]) and importance sampled by luminance, as pbrt-v4's
//! `ImageInfiniteLight`.
//!
//! Sampling draws image coordinates `(s, t)` (`s` = u, `t` = rows from the top) from a
//! piecewise-constant distribution over the texels, then maps them to a direction. A texel
//! row at latitude `λ` covers a solid angle ∝ `cos λ`, so the weights carry that factor and the
//! density in solid angle is `p(ω) = p(s, t) / (2π² cos λ)`.

use raylab_core::color::luminance;
use raylab_core::{Distribution2D, Rgb, Vec2, Vec3};
use rayon::prelude::*;
use std::f32::consts::PI;

use crate::texture::{equirect_dir, equirect_uv, ImageTexture};

#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    image: ImageTexture,
    scale: Rgb,
    distribution: Distribution2D,
}

/// A direction towards the environment.
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentSample {
    pub wi: Vec3,
    /// Radiance arriving from `wi`.
    pub le: Rgb,
    /// Density in solid angle.
    pub pdf: f32,
}

impl EnvironmentLight {
    /// `image` scaled by `scale`. The sampling weight of a texel is the mean luminance of the
    /// bilinearly filtered map over the texel's area (a 4×4 grid of lookups, as pbrt-v4's
    /// `GetSamplingDistribution`): the density then follows what lookups return, and stays
    /// non-zero wherever the filter spreads radiance from a neighbour.
    pub fn new(image: ImageTexture, scale: Rgb) -> Self {
        let (w, h) = (image.width() as usize, image.height() as usize);
        let mut weights = vec![0.0f32; w * h];
        weights.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            let cos_lat = (PI * (0.5 - (y as f32 + 0.5) / h as f32)).cos();
            for (x, weight) in row.iter_mut().enumerate() {
                let mut sum = 0.0f32;
                for j in 0..4 {
                    for i in 0..4 {
                        let s = (x as f32 + (i as f32 + 0.5) / 4.0) / w as f32;
                        let t = (y as f32 + (j as f32 + 0.5) / 4.0) / h as f32;
                        sum += luminance(image.lookup(Vec2::new(s, 1.0 - t)) * scale).max(0.0);
                    }
                }
                *weight = sum / 16.0 * cos_lat;
            }
        });
        Self { distribution: Distribution2D::new(&weights, w, h), image, scale }
    }

    /// Why `image` cannot be an environment map, if it cannot: it gives radiance, which is
    /// never negative (an HDR file may hold negative values, which would render as
    /// negative pixels) and always finite.
    pub fn check_image(image: &ImageTexture) -> Result<(), String> {
        let w = image.width() as usize;
        match image.texels().iter().position(|t| !t.is_finite() || t.min_element() < 0.0) {
            Some(i) => {
                let t = image.texels()[i];
                Err(format!("texel ({}, {}) is [{}, {}, {}]: an environment map's radiance must be finite and not negative", i % w, i / w, t.x, t.y, t.z))
            }
            None => Ok(()),
        }
    }

    /// Radiance arriving from direction `dir` (any length).
    pub fn radiance(&self, dir: Vec3) -> Rgb {
        self.image.lookup(equirect_uv(dir)) * self.scale
    }

    /// Whether the map is black everywhere (nothing to sample).
    pub fn is_black(&self) -> bool {
        self.distribution.integral() <= 0.0
    }

    /// A direction drawn in proportion to luminance × solid angle.
    pub fn sample(&self, u: Vec2) -> Option<EnvironmentSample> {
        if self.is_black() {
            return None;
        }
        let (st, pdf_st) = self.distribution.sample(u);
        let wi = equirect_dir(Vec2::new(st.x, 1.0 - st.y));
        let cos_lat = (1.0 - wi.y * wi.y).max(0.0).sqrt();
        if pdf_st <= 0.0 || cos_lat <= 0.0 {
            return None;
        }
        Some(EnvironmentSample { wi, le: self.radiance(wi), pdf: pdf_st / (2.0 * PI * PI * cos_lat) })
    }

    /// The density [`EnvironmentLight::sample`] gives direction `dir` (unit).
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let cos_lat = (1.0 - dir.y * dir.y).max(0.0).sqrt();
        if self.is_black() || cos_lat <= 0.0 {
            return 0.0;
        }
        let uv = equirect_uv(dir);
        self.distribution.pdf(Vec2::new(uv.x, 1.0 - uv.y)) / (2.0 * PI * PI * cos_lat)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{Filter, Wrap};
    use raylab_core::{sampling, Pcg32};

    /// A dark map with one bright texel: a small sun.
    fn sun_map() -> EnvironmentLight {
        let (w, h) = (32, 16);
        let mut texels = vec![Rgb::splat(0.05); w * h];
        texels[4 * w + 20] = Rgb::new(400.0, 300.0, 200.0);
        EnvironmentLight::new(ImageTexture::new(w as u32, h as u32, texels, Wrap::Repeat, Filter::Bilinear).unwrap(), Rgb::ONE)
    }

    #[test]
    fn sampled_density_matches_pdf_and_integrates_to_one() {
        let env = sun_map();
        let mut rng = Pcg32::new(3, 0);
        for _ in 0..2000 {
            let s = env.sample(rng.next_vec2()).unwrap();
            assert!((s.wi.length() - 1.0).abs() < 1e-5);
            let pdf = env.pdf(s.wi);
            assert!((s.pdf - pdf).abs() <= 1e-3 * pdf, "{} vs {pdf}", s.pdf);
        }
        // ∫ p(ω) dω = 1, estimated with uniform directions.
        let n = 400_000;
        let mean: f64 = (0..n).map(|_| env.pdf(sampling::uniform_sphere(rng.next_vec2())) as f64).sum::<f64>() / n as f64;
        assert!((mean * 4.0 * std::f64::consts::PI - 1.0).abs() < 0.03, "∫p = {}", mean * 4.0 * std::f64::consts::PI);
    }

    #[test]
    fn importance_sampling_estimates_irradiance_with_far_less_variance_than_uniform() {
        // E = ∫ L(ω) max(0, ω·n) dω over the upper hemisphere of n = +y.
        let env = sun_map();
        let n = Vec3::Y;
        let mut rng = Pcg32::new(11, 0);
        let count = 20_000;
        let stats = |samples: Vec<f64>| {
            let m = samples.iter().sum::<f64>() / samples.len() as f64;
            let v = samples.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (samples.len() - 1) as f64;
            (m, v)
        };
        let (m_is, v_is) = stats((0..count).map(|_| {
            let s = env.sample(rng.next_vec2()).unwrap();
            (luminance(s.le) * s.wi.dot(n).max(0.0) / s.pdf) as f64
        }).collect());
        let (m_u, v_u) = stats((0..count).map(|_| {
            let w = sampling::uniform_sphere(rng.next_vec2());
            (luminance(env.radiance(w)) * w.dot(n).max(0.0) * 4.0 * PI) as f64
        }).collect());
        let se = (v_u / count as f64).sqrt() + (v_is / count as f64).sqrt();
        assert!((m_is - m_u).abs() < 4.0 * se, "IS {m_is} vs uniform {m_u} (±{se})");
        assert!(v_is * 20.0 < v_u, "variance IS {v_is}, uniform {v_u}");
    }

    /// A 4 × 2 grey map, nearest-texel lookups (so each texel's 16 weight lookups return the
    /// texel itself), luminances [1, 2, 3, 4] in the top row (latitudes 0 to 90° north) and
    /// [0, 0, 0, 2] in the bottom one, scaled by (2, 1, 0.5).
    fn tiny_map() -> EnvironmentLight {
        let texels = [1.0, 2.0, 3.0, 4.0, 0.0, 0.0, 0.0, 2.0].map(Rgb::splat).to_vec();
        EnvironmentLight::new(ImageTexture::new(4, 2, texels, Wrap::Repeat, Filter::Nearest).unwrap(), Rgb::new(2.0, 1.0, 0.5))
    }

    /// The direction at longitude fraction `s` (u) and latitude `lat` (radians north): the
    /// equirectangular map has φ = 2π(s − ½) from +x towards +z, +y up.
    fn dir(s: f32, lat: f32) -> Vec3 {
        let phi = 2.0 * PI * (s - 0.5);
        Vec3::new(lat.cos() * phi.cos(), lat.sin(), lat.cos() * phi.sin())
    }

    #[test]
    fn tiny_map_densities_and_radiance_by_hand() {
        // Both rows' centres lie at ±45°, so the cos λ weights are equal and the texel density
        // over the image square is luminance / mean luminance = L / (12/8) = L / 1.5 (the scale
        // multiplies every weight by the same luminance(2, 1, 0.5) and cancels). In solid angle
        // p(ω) = p(s, t) / (2π² cos λ) at the direction's own latitude λ.
        let env = tiny_map();
        let scale = Rgb::new(2.0, 1.0, 0.5);
        let pi2 = PI * PI;
        let cases = [
            // (s, λ, texel luminance): texel (3, 0) at its centre, (1, 0) at 60°, (3, 1) at −30°,
            // (0, 1) (black) at −45°.
            (0.875, PI / 4.0, 4.0),
            (0.375, PI / 3.0, 2.0),
            (0.875, -PI / 6.0, 2.0),
            (0.125, -PI / 4.0, 0.0),
        ];
        for (s, lat, l) in cases {
            let w = dir(s, lat);
            let expected = l / 1.5 / (2.0 * pi2 * lat.cos());
            assert!((env.pdf(w) - expected).abs() <= 1e-5 * expected.max(1e-3), "s {s}, λ {lat}: {} against {expected}", env.pdf(w));
            assert!((env.radiance(w) - scale * l).abs().max_element() < 1e-5, "s {s}, λ {lat}: {}", env.radiance(w));
        }
        // The centre of texel (3, 0) worked out: φ = 3π/4, λ = π/4, p = (8/3) / (√2·π²).
        let w = Vec3::new(-0.5, std::f32::consts::FRAC_1_SQRT_2, 0.5);
        assert!((env.pdf(w) - 8.0 / 3.0 / (2f32.sqrt() * pi2)).abs() < 1e-6, "{}", env.pdf(w));
        // At the poles the rows' solid angle vanishes: no density, and a sample that lands on
        // the north pole (u.y = 0 is the top of row 0, t = 0) is refused.
        assert_eq!(env.pdf(Vec3::Y), 0.0);
        assert_eq!(env.pdf(-Vec3::Y), 0.0);
        assert!(env.sample(Vec2::new(0.3, 0.0)).is_none());
    }

    #[test]
    fn tiny_map_samples_texels_in_proportion_to_luminance() {
        // A regular 120 × 120 grid of u through the inverse CDFs: row 0 takes 10/12 of u.y
        // (100 of 120 rows), and within it texel x takes (x + 1)/10 of u.x; row 1 takes 20 rows
        // and all of them texel 3. Every sample reports the radiance and the density of the
        // texel its direction lies in, by hand as above.
        let env = tiny_map();
        let lum = [[1.0f32, 2.0, 3.0, 4.0], [0.0, 0.0, 0.0, 2.0]];
        let mut counts = [[0u32; 4]; 2];
        let n = 120;
        for (i, j) in (0..n * n).map(|k| (k % n, k / n)) {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let smp = env.sample(u).unwrap();
            let w = smp.wi;
            assert!((w.length() - 1.0).abs() < 1e-5, "{w}");
            let s = 0.5 + w.z.atan2(w.x) / (2.0 * PI);
            let lat = w.y.clamp(-1.0, 1.0).asin();
            let (x, y) = (((s * 4.0) as usize).min(3), if lat > 0.0 { 0 } else { 1 });
            counts[y][x] += 1;
            let l = lum[y][x];
            assert!(l > 0.0, "u {u}: sampled the black texel ({x}, {y})");
            assert!((smp.le - Rgb::new(2.0, 1.0, 0.5) * l).abs().max_element() < 1e-5, "u {u}: {}", smp.le);
            let expected = l / 1.5 / (2.0 * PI * PI * lat.cos());
            assert!((smp.pdf - expected).abs() <= 1e-4 * expected, "u {u}: pdf {} against {expected}", smp.pdf);
        }
        let expected = [[1200u32, 2400, 3600, 4800], [0, 0, 0, 2400]];
        for (y, (got, want)) in counts.iter().zip(&expected).enumerate() {
            for (x, (&c, &e)) in got.iter().zip(want).enumerate() {
                assert!(c.abs_diff(e) <= 2 * n as u32, "texel ({x}, {y}): {c} against {e}");
            }
        }
    }

    #[test]
    fn check_image_rejects_negative_texels_only() {
        let image = |bad: Rgb| ImageTexture::new(3, 2, vec![Rgb::ONE, Rgb::ONE, Rgb::ONE, Rgb::ONE, bad, Rgb::ONE], Wrap::Repeat, Filter::Bilinear).unwrap();
        // Zero (and −0) radiance is fine; texel 4 of a 3-wide image is (1, 1).
        assert_eq!(EnvironmentLight::check_image(&image(Rgb::ZERO)), Ok(()));
        assert_eq!(EnvironmentLight::check_image(&image(Rgb::new(-0.0, 0.0, 5.0))), Ok(()));
        // (`ImageTexture::new` itself refuses non-finite texels.)
        for bad in [Rgb::new(1.0, -1e-3, 1.0), Rgb::new(1.0, 1.0, -5.0)] {
            let err = EnvironmentLight::check_image(&image(bad)).unwrap_err();
            assert!(err.starts_with("texel (1, 1) is ["), "{bad}: {err}");
        }
    }

    #[test]
    fn black_map_samples_nothing() {
        let black = ImageTexture::new(4, 2, vec![Rgb::ZERO; 8], Wrap::Repeat, Filter::Bilinear).unwrap();
        let env = EnvironmentLight::new(black, Rgb::ONE);
        assert!(env.sample(Vec2::splat(0.5)).is_none());
        assert_eq!(env.pdf(Vec3::X), 0.0);
    }
}
