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
    // In 64 bits: `i + p` in u32 (as Kensler prints it) wraps for p > 2³² − 1 − i, where the
    // result is no longer a permutation (and a debug build panics).
    ((i as u64 + p as u64) % n as u64) as u32
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

    #[test]
    fn check_spp_accepts_squares_for_jittered_only() {
        assert_eq!(SamplerKind::Random.check_spp(0).unwrap_err(), "must be at least 1");
        assert_eq!(SamplerKind::Jittered.check_spp(0).unwrap_err(), "must be at least 1");
        // 9 = 3·3 and 16 = 4·4, where n + n (6, 8) and n / n (1) are not the square.
        for spp in [1, 4, 9, 16, 25, 1024] {
            assert_eq!(SamplerKind::Jittered.check_spp(spp), Ok(()), "{spp}");
        }
        for spp in [2, 3, 8, 15, 17] {
            assert_eq!(SamplerKind::Jittered.check_spp(spp).unwrap_err(), format!("the jittered sampler needs a square number of samples (1, 4, 9, 16, ...), found {spp}"));
            assert_eq!(SamplerKind::Random.check_spp(spp), Ok(()));
            assert_eq!(SamplerKind::Sobol.check_spp(spp), Ok(()));
        }
    }

    #[test]
    fn to_unit_keeps_the_top_24_bits() {
        // v / 2³² truncated to 24 bits: the low 8 bits are dropped, and the largest value is
        // (2²⁴ − 1)/2²⁴ = 1 − 2⁻²⁴, exact in f32.
        assert_eq!(to_unit(0), 0.0);
        assert_eq!(to_unit(0xff), 0.0);
        assert_eq!(to_unit(0x100), 2f32.powi(-24));
        assert_eq!(to_unit(0x8000_0000), 0.5);
        assert_eq!(to_unit(0xc000_00ff), 0.75);
        assert_eq!(to_unit(u32::MAX), 1.0 - 2f32.powi(-24));
    }

    #[test]
    fn sobol_02_second_dimension_follows_its_direction_numbers() {
        // v₁ = .1, v₂ = .11, v₃ = .101 (binary; each v_k = v_{k−1} ^ (v_{k−1} >> 1)), y(i) the
        // xor of v_k over the set bits k of i: y(4) = .101, y(5) = .1 ^ .101 = .001,
        // y(6) = .11 ^ .101 = .011, y(7) = .1 ^ .11 ^ .101 = .111. x is i's bits mirrored.
        let p: Vec<(f64, f64)> = (4..8).map(sobol_02).map(|(a, b)| (a as f64 / 2f64.powi(32), b as f64 / 2f64.powi(32))).collect();
        assert_eq!(p, [(0.125, 0.625), (0.625, 0.125), (0.375, 0.375), (0.875, 0.875)]);
        // y(2^k) = v_{k+1}, whose bits are row k of Pascal's triangle mod 2: row 4 is 1 0 0 0 1,
        // row 7 is 1 1 1 1 1 1 1 1.
        assert_eq!(sobol_02(16).1, 0b10001 << 27);
        assert_eq!(sobol_02(128).1, 0xff00_0000);
    }

    #[test]
    fn owen_scrambling_permutes_every_level_of_nested_intervals() {
        // An Owen scramble flips each bit of the fraction by a function of the bits above it:
        // the top k bits of the result depend only on the top k bits of the input, and map
        // the 2^k intervals of length 2⁻ᵏ one-to-one onto themselves.
        let mut rng = Pcg32::new(5, 9);
        for _ in 0..40 {
            let seed = rng.next_u32();
            for k in 1..=8u32 {
                let mut seen = vec![false; 1 << k];
                for top in 0..1u32 << k {
                    let v = top << (32 - k);
                    let out = owen_scramble(v, seed) >> (32 - k);
                    assert!(!std::mem::replace(&mut seen[out as usize], true), "seed {seed:#x}, {k} bits: {top} and another both to {out}");
                    let low = rng.next_u32() >> k;
                    assert_eq!(owen_scramble(v | low, seed) >> (32 - k), out, "seed {seed:#x}: lower bits changed the top {k}");
                }
            }
        }
        // The seed decides the flips: the first bit of 0's image is 1 for about half the seeds.
        let ones = (0..1000).filter(|_| owen_scramble(0, rng.next_u32()) >> 31 == 1).count();
        assert!((400..600).contains(&ones), "{ones} of 1000");
    }

    /// Sorted values of one coordinate of dimension `dim` over a pixel's `spp` samples.
    fn sorted(kind: SamplerKind, spp: u32, x: u32, dim: usize, coord: usize) -> Vec<f32> {
        let mut v: Vec<f32> = points(kind, spp, x, dim + 1).iter().map(|p| if coord == 0 { p[dim].x } else { p[dim].y }).collect();
        v.sort_by(f32::total_cmp);
        v
    }

    #[test]
    fn sobol_values_are_scrambled_per_pixel_and_dimension() {
        // With 16 samples each coordinate has one value in each sixteenth ((0,4,1)-net), but
        // where in it depends on the pixel's and dimension's scramble: the sorted values of
        // two pixels (or of two dimensions) are not the same.
        for coord in 0..2 {
            let (a, b, c) = (sorted(SamplerKind::Sobol, 16, 1, 0, coord), sorted(SamplerKind::Sobol, 16, 2, 0, coord), sorted(SamplerKind::Sobol, 16, 1, 1, coord));
            for v in [&a, &b, &c] {
                assert!(v.iter().enumerate().all(|(i, &x)| (x * 16.0) as usize == i), "{coord}: {v:?}");
            }
            assert!(a != b && a != c, "coordinate {coord}: {a:?} {b:?} {c:?}");
        }
        // The same for 1D values (dimension 0 of two pixels, or dimensions 0 and 1).
        let one_d = |x: u32, dim: usize| {
            let mut v: Vec<f32> = (0..16)
                .map(|i| {
                    let mut s = PixelSampler::new(SamplerKind::Sobol, 16, 3, x, 7, i);
                    for _ in 0..dim {
                        s.get_1d();
                    }
                    s.get_1d()
                })
                .collect();
            v.sort_by(f32::total_cmp);
            v
        };
        let (a, b, c) = (one_d(1, 0), one_d(2, 0), one_d(1, 1));
        for v in [&a, &b, &c] {
            assert!(v.iter().enumerate().all(|(i, &x)| (x * 16.0) as usize == i), "{v:?}");
        }
        assert!(a != b && a != c, "{a:?} {b:?} {c:?}");
    }

    #[test]
    fn dimension_hashes_are_one_to_one() {
        // For a fixed dimension d the hash is a bijection of the pixel's hash (xor with d·φ,
        // φ = 0x9e37_79b9_7f4a_7c15 odd, then mix64), so two pixels never share a dimension's
        // shuffle and scramble: pixel hashes 0 and φ differ at dimension 1 too (0 ^ φ and
        // φ ^ φ = 0; an `|` would take both to φ).
        let sampler = |pixel_hash| PixelSampler { kind: SamplerKind::Sobol, spp: 16, index: 0, dim: 0, pixel_hash, rng: Pcg32::new(0, 0) };
        let (mut a, mut b) = (sampler(0), sampler(0x9e37_79b9_7f4a_7c15));
        for d in 0..64 {
            assert_ne!(a.dimension_hash(), b.dimension_hash(), "dimension {d}");
        }
        // For a fixed pixel, d ↦ d·φ is one-to-one mod 2⁶⁴: 1000 dimensions, 1000 hashes.
        let mut s = sampler(0x1234_5678_9abc_def0);
        let mut seen = std::collections::HashSet::new();
        for d in 0..1000 {
            assert!(seen.insert(s.dimension_hash()), "dimension {d}");
        }
    }

    #[test]
    fn the_pixel_position_is_the_first_stratified_pair() {
        // Jittered with 4 samples: one film position in each quadrant of the pixel, and the
        // same values as the first get_2d of an identical sampler.
        let mut quadrants = [0; 4];
        for i in 0..4 {
            let p = PixelSampler::new(SamplerKind::Jittered, 4, 1, 2, 3, i).pixel_2d();
            assert_eq!(p, PixelSampler::new(SamplerKind::Jittered, 4, 1, 2, 3, i).get_2d());
            quadrants[(p.x >= 0.5) as usize + 2 * (p.y >= 0.5) as usize] += 1;
        }
        assert_eq!(quadrants, [1; 4]);
    }

    /// Kensler 2013 ("Correlated Multi-Jittered Sampling", Pixar Technical Memo 13-01), the
    /// listing of `permute(i, l, p)` transcribed as printed (C `unsigned` arithmetic, a
    /// do-while cycle walk): the reference for `permutation_element`.
    fn kensler_permute(mut i: u32, l: u32, p: u32) -> u32 {
        let mut w = l - 1;
        w |= w >> 1;
        w |= w >> 2;
        w |= w >> 4;
        w |= w >> 8;
        w |= w >> 16;
        loop {
            i ^= p;
            i = i.wrapping_mul(0xe170893d);
            i ^= p >> 16;
            i ^= (i & w) >> 4;
            i ^= p >> 8;
            i = i.wrapping_mul(0x0929eb3f);
            i ^= p >> 23;
            i ^= (i & w) >> 1;
            i = i.wrapping_mul(1 | p >> 27);
            i = i.wrapping_mul(0x6935fa69);
            i ^= (i & w) >> 11;
            i = i.wrapping_mul(0x74dcb303);
            i ^= (i & w) >> 2;
            i = i.wrapping_mul(0x9e501cc3);
            i ^= (i & w) >> 2;
            i = i.wrapping_mul(0xc860a3df);
            i &= w;
            i ^= i >> 5;
            if i < l {
                // The sum in 64 bits: C's 32-bit sum wraps for p > 2³² − 1 − i (see below).
                return ((i as u64 + p as u64) % l as u64) as u32;
            }
        }
    }

    #[test]
    fn permutations_are_kenslers() {
        // Any permutation keeps the strata, so only the published function can tell a changed
        // shift or mask apart; the images' reproducibility depends on it. Powers of two (the
        // mask exactly n − 1, no cycle walk) and not, and seeds with every shifted part set.
        // Indices past n wrap (i mod n) before the walk. The step `(i & w) >> 11` is 0 below
        // n = 2¹¹ + 1, hence 4096 and 5000.
        for n in [2u32, 3, 5, 16, 17, 64, 100, 1000, 4096, 5000] {
            for p in [0u32, 1, 0x8000_0001, 0xdead_beef, 0x1234_5678, 0xffff_ffff] {
                for i in 0..n {
                    assert_eq!(permutation_element(i, n, p), kensler_permute(i, n, p), "i {i}, n {n}, p {p:#x}");
                    assert_eq!(permutation_element(i + n, n, p), kensler_permute(i, n, p), "i {} wraps, n {n}, p {p:#x}", i + n);
                }
            }
        }
    }

    #[test]
    fn seeds_near_the_top_still_give_permutations() {
        // A bug, fixed: `(i + p) % n` in u32 overflowed for p > 2³² − 1 − i (a hash of a pixel
        // and dimension, so about i/2³² of the calls): a panic in debug builds, and in release
        // not a permutation: n = 3, p = 2³² − 1 wrapped 1 + p to 0 and 2 + p to 1, while 0 + p
        // ≡ 0 (mod 3, as 2³² ≡ 1), so two samples shared stratum 0.
        for (n, p) in [(3u32, u32::MAX), (16, u32::MAX), (16, u32::MAX - 15), (1000, u32::MAX), (1000, u32::MAX - 999)] {
            let mut seen = vec![false; n as usize];
            for i in 0..n {
                let e = permutation_element(i, n, p);
                assert!(!std::mem::replace(&mut seen[e as usize], true), "n {n} p {p:#x}: {e} twice");
            }
        }
    }

    /// pbrt-v4's `FastOwenScrambler` (after Burley 2020, "Practical Hash-based Owen
    /// Scrambling"), transcribed: the reference for `owen_scramble`.
    fn pbrt_fast_owen(v: u32, seed: u32) -> u32 {
        let mut v = v.reverse_bits();
        v ^= v.wrapping_mul(0x3d20adea);
        v = v.wrapping_add(seed);
        v = v.wrapping_mul((seed >> 16) | 1);
        v ^= v.wrapping_mul(0x05526c56);
        v ^= v.wrapping_mul(0x53a22864);
        v.reverse_bits()
    }

    #[test]
    fn owen_scrambling_is_pbrts() {
        // The nesting test above holds for any multiplier (seed >> 16) | 1 that is odd; the
        // published hash pins which.
        let mut rng = Pcg32::new(11, 3);
        for _ in 0..200 {
            let (v, seed) = (rng.next_u32(), rng.next_u32());
            assert_eq!(owen_scramble(v, seed), pbrt_fast_owen(v, seed), "v {v:#x}, seed {seed:#x}");
        }
    }
}
