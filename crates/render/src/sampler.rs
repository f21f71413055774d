//! Sample values for one pixel sample: the film position first, then as many 1D and 2D
//! values as the integrator asks for (lens, light choice, BSDF lobes, ...), each
//! "dimension" drawn from its own decorrelated pattern (pbrt-v4's sampler interface).
//!
//! - `random`: independent uniform values from the pixel's PCG32 stream.
//! - `jittered`: every dimension stratified over the pixel's `spp` samples (an `n × n`
//!   grid for 2D, `spp = n²`), strata shuffled per pixel and dimension so that dimensions
//!   do not correlate (pbrt-v4's `StratifiedSampler`).
//! - `sobol`: the 2D Sobol (0,2)-sequence for every dimension pair, Owen-scrambled and
//!   index-shuffled per pixel and dimension (pbrt-v4's `PaddedSobolSampler`), so any power
//!   of two `spp` is a (0,m,2)-net in every pair of dimensions.

use raylab_core::rng::mix64;
use raylab_core::{sampling, Pcg32, Vec2};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    Random,
    Jittered,
    Sobol,
}

raylab_core::named_enum!(SamplerKind, "sampler", {
    Random => "random",
    Jittered => "jittered",
    Sobol => "sobol",
});

impl SamplerKind {
    /// Checks that `spp` suits the sampler.
    pub fn check_spp(self, spp: u32) -> Result<(), String> {
        if spp == 0 {
            return Err("must be at least 1".into());
        }
        if self == SamplerKind::Jittered {
            let n = (spp as f64).sqrt().round() as u32;
            if n * n != spp {
                return Err(format!("the jittered sampler needs a square number of samples (1, 4, 9, 16, ...), found {spp}"));
            }
        }
        Ok(())
    }
}

/// The values of sample `index` of one pixel. Deterministic in (seed, pixel, index), so
/// images do not depend on the thread count or tile order.
pub struct PixelSampler {
    kind: SamplerKind,
    spp: u32,
    index: u32,
    dim: u32,
    pixel_hash: u64,
    rng: Pcg32,
}

impl PixelSampler {
    pub fn new(kind: SamplerKind, spp: u32, seed: u64, x: u32, y: u32, index: u32) -> Self {
        let pixel_hash = mix64(seed ^ mix64(((x as u64) << 32) | y as u64));
        let rng = Pcg32::new(pixel_hash, index as u64);
        Self { kind, spp: spp.max(1), index, dim: 0, pixel_hash, rng }
    }

    /// A hash of this pixel and the next dimension, for shuffles and scrambles.
    fn dimension_hash(&mut self) -> u64 {
        let h = mix64(self.pixel_hash ^ (self.dim as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        self.dim += 1;
        h
    }

    pub fn get_1d(&mut self) -> f32 {
        match self.kind {
            SamplerKind::Random => self.rng.next_f32(),
            SamplerKind::Jittered => {
                let h = self.dimension_hash();
                let stratum = permutation_element(self.index, self.spp, h as u32);
                (stratum as f32 + self.rng.next_f32()) / self.spp as f32
            }
            SamplerKind::Sobol => {
                let h = self.dimension_hash();
                let i = permutation_element(self.index, self.spp, h as u32);
                to_unit(owen_scramble(i.reverse_bits(), (h >> 32) as u32))
            }
        }
    }

    pub fn get_2d(&mut self) -> Vec2 {
        match self.kind {
            SamplerKind::Random => self.rng.next_vec2(),
            SamplerKind::Jittered => {
                let h = self.dimension_hash();
                let n = (self.spp as f32).sqrt().round().max(1.0) as u32;
                let stratum = permutation_element(self.index, n * n, h as u32);
                sampling::jittered(stratum, n, self.rng.next_vec2())
            }
            SamplerKind::Sobol => {
                let h = self.dimension_hash();
                let i = permutation_element(self.index, self.spp, h as u32);
                let (a, b) = sobol_02(i);
                let h2 = mix64(h);
                Vec2::new(to_unit(owen_scramble(a, (h >> 32) as u32)), to_unit(owen_scramble(b, (h2 >> 32) as u32)))
            }
        }
    }

    /// The position in the pixel, `[0,1)²`: always the first dimension pair.
    pub fn pixel_2d(&mut self) -> Vec2 {
        debug_assert_eq!(self.dim, 0, "the film position is the first dimension");
        self.get_2d()
    }
}

/// The `i`th point of the 2D Sobol (0,2)-sequence as 32-bit fixed-point fractions: van der
/// Corput in the first coordinate, the second Sobol dimension (primitive polynomial x + 1,
/// direction numbers `v_k = v_{k-1} ^ (v_{k-1} >> 1)`) in the second.
fn sobol_02(i: u32) -> (u32, u32) {
    let mut v = 1u32 << 31;
    let mut y = 0u32;
    let mut bits = i;
    while bits != 0 {
        if bits & 1 != 0 {
            y ^= v;
        }
        bits >>= 1;
        v ^= v >> 1;
    }
    (i.reverse_bits(), y)
}

/// Owen scrambling by a hash of the bits above each bit (Burley 2020's fast approximation,
/// as in pbrt-v4's `FastOwenScrambler`): keeps the (0,m,2)-net property of the points.
fn owen_scramble(v: u32, seed: u32) -> u32 {
    let mut v = v.reverse_bits();
    v ^= v.wrapping_mul(0x3d20_adea);
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6c56);
    v ^= v.wrapping_mul(0x53a2_2864);
    v.reverse_bits()
}

/// A 32-bit fixed-point fraction as a float strictly below 1.
fn to_unit(v: u32) -> f32 {
    ((v >> 8) as f32 * (1.0 / (1u32 << 24) as f32)).min(1.0 - f32::EPSILON / 2.0)
}

/// Element `i` of a pseudo-random permutation of `0..n` chosen by `p` (Kensler 2013,
/// "Correlated Multi-Jittered Sampling", cycle-walking an invertible hash).
fn permutation_element(mut i: u32, n: u32, p: u32) -> u32 {
    if n <= 1 {
        return 0;
    }
    let mut w = n - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    i %= n;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < n {
            break;
        }
    }
    (i + p) % n
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points(kind: SamplerKind, spp: u32, x: u32, dims: usize) -> Vec<Vec<Vec2>> {
        (0..spp)
            .map(|i| {
                let mut s = PixelSampler::new(kind, spp, 3, x, 7, i);
                (0..dims).map(|_| s.get_2d()).collect()
            })
            .collect()
    }

    #[test]
    fn sobol_02_starts_with_the_known_points() {
        let p: Vec<(f64, f64)> = (0..4).map(sobol_02).map(|(a, b)| (a as f64 / 2f64.powi(32), b as f64 / 2f64.powi(32))).collect();
        assert_eq!(p, [(0.0, 0.0), (0.5, 0.5), (0.25, 0.75), (0.75, 0.25)]);
    }

    #[test]
    fn permutations_are_permutations() {
        for n in [1, 2, 3, 7, 16, 100, 1000] {
            for p in [0u32, 1, 0xdead_beef] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let e = permutation_element(i, n, p) as usize;
                    assert!(!std::mem::replace(&mut seen[e], true), "n {n} p {p}: {e} twice");
                }
            }
        }
    }

    /// Every elementary interval of area 1/n (1×n, 2×n/2, ..., n×1) holds one point.
    fn is_02_net(pts: &[Vec2]) -> bool {
        let n = pts.len() as u32;
        let mut a = 1;
        while a <= n {
            let b = n / a;
            let mut count = vec![0; n as usize];
            for p in pts {
                let (i, j) = ((p.x * a as f32) as u32, (p.y * b as f32) as u32);
                count[(j * a + i) as usize] += 1;
            }
            if count.iter().any(|&c| c != 1) {
                return false;
            }
            a *= 2;
        }
        true
    }

    #[test]
    fn sobol_is_a_02_net_in_every_dimension_pair() {
        for spp in [4, 16, 64] {
            let pts = points(SamplerKind::Sobol, spp, 11, 5);
            for d in 0..5 {
                let dim: Vec<Vec2> = pts.iter().map(|p| p[d]).collect();
                assert!(is_02_net(&dim), "spp {spp}, dimension {d}");
            }
        }
        // Random points are not (with this seed), so the check can fail.
        let pts = points(SamplerKind::Random, 16, 11, 1);
        assert!(!is_02_net(&pts.iter().map(|p| p[0]).collect::<Vec<_>>()));
    }

    #[test]
    fn jittered_fills_every_stratum_once_in_every_dimension() {
        let spp = 16;
        let pts = points(SamplerKind::Jittered, spp, 5, 4);
        for d in 0..4 {
            let mut cells = [0; 16];
            for p in &pts {
                let c = (p[d].y * 4.0) as usize * 4 + (p[d].x * 4.0) as usize;
                cells[c] += 1;
            }
            assert_eq!(cells, [1; 16], "dimension {d}");
        }
        let mut strata = [0; 16];
        for i in 0..spp {
            let mut s = PixelSampler::new(SamplerKind::Jittered, spp, 3, 5, 7, i);
            strata[(s.get_1d() * 16.0) as usize] += 1;
        }
        assert_eq!(strata, [1; 16]);
    }

    #[test]
    fn dimensions_and_pixels_are_decorrelated() {
        // Two dimensions of one pixel, or one dimension of two pixels, differ.
        let a = points(SamplerKind::Sobol, 16, 1, 2);
        let b = points(SamplerKind::Sobol, 16, 2, 2);
        assert!(a.iter().zip(&b).any(|(p, q)| p[0] != q[0]));
        assert!(a.iter().any(|p| p[0] != p[1]));
    }

    #[test]
    fn better_patterns_integrate_better() {
        // RMS error of estimating ∫∫ exp(-(x² + y²)) over the unit square with 64 samples
        // per pixel, over 200 pixels: stratification beats independence, Sobol beats both.
        let exact = {
            let erf_1 = 0.842_700_79_f64;
            (std::f64::consts::PI.sqrt() / 2.0 * erf_1).powi(2)
        };
        let rmse = |kind| {
            let mut sum = 0.0;
            for x in 0..200 {
                let est: f64 = (0..64)
                    .map(|i| {
                        let mut s = PixelSampler::new(kind, 64, 9, x, 0, i);
                        s.get_2d();
                        let p = s.get_2d();
                        (-(p.x * p.x + p.y * p.y) as f64).exp()
                    })
                    .sum::<f64>()
                    / 64.0;
                sum += (est - exact).powi(2);
            }
            (sum / 200.0).sqrt()
        };
        let (r, j, s) = (rmse(SamplerKind::Random), rmse(SamplerKind::Jittered), rmse(SamplerKind::Sobol));
        assert!(j < 0.5 * r && s < j, "random {r}, jittered {j}, sobol {s}");
    }

    #[test]
    fn values_stay_in_the_unit_interval() {
        for kind in SamplerKind::ALL {
            for i in 0..256 {
                let mut s = PixelSampler::new(*kind, 256, 1, 0, 0, i);
                for _ in 0..8 {
                    let (a, p) = (s.get_1d(), s.get_2d());
                    assert!((0.0..1.0).contains(&a) && (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
                }
            }
        }
    }
}
