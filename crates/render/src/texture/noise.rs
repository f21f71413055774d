//! Solid noise textures: Perlin's improved noise (Perlin 2002, "Improving Noise") with the
//! turbulence, marble and wood patterns of *Ray Tracing: The Next Week* and Perlin 1985.
//!
//! The permutation table is shuffled by a seeded [`Pcg32`], so two scenes with the same seed
//! render the same marble, and two noise textures in one scene can differ.

use std::f32::consts::TAU;

use raylab_core::{Pcg32, Rgb, Vec3};

/// Which pattern a [`Noise`] texture draws from the noise field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NoiseKind {
    /// The noise itself, `0.5 (1 + noise(scale p))`: soft blobs.
    #[default]
    Plain,
    /// `|Σ noise(2^i scale p) / 2^i|` over `octaves`: the book's turbulence (clouds, smoke).
    Turbulence,
    /// `0.5 (1 + sin(scale p.z + 10 turb(p)))`: veins along z, perturbed by turbulence, exactly
    /// as the book's marble (turbulence taken at the unscaled point).
    Marble,
    /// Concentric rings around the y axis, `scale` rings per unit of radius, perturbed by
    /// turbulence so they wobble like grain: `0.5 (1 - cos 2π (scale r + turb(p)))`.
    Wood,
}

raylab_core::named_enum!(NoiseKind, "noise kind", {
    Plain => "plain",
    Turbulence => "turbulence",
    Marble => "marble",
    Wood => "wood",
});

/// Octaves beyond this add less than 2^-16 of the signal, below any 8-bit or half-float output.
const MAX_OCTAVES: u32 = 16;

/// A seeded Perlin-noise solid texture blending two colours.
#[derive(Clone, Debug)]
pub struct Noise {
    /// The pattern.
    pub kind: NoiseKind,
    /// Frequency: features per unit of object space (for marble, the vein frequency along z).
    pub scale: f32,
    /// `colors[0]` where the pattern is 0, `colors[1]` where it is 1, linear blend between.
    pub colors: [Rgb; 2],
    /// Octaves summed by turbulence (used by every kind but `Plain`); read as `1..=16`.
    pub octaves: u32,
    /// Perlin's permutation of 0..256, stored twice so `perm[i + 1]` needs no wrap.
    perm: Box<[u8; 512]>,
}

impl Noise {
    /// A noise texture whose permutation is shuffled from `seed`.
    pub fn new(kind: NoiseKind, scale: f32, colors: [Rgb; 2], octaves: u32, seed: u64) -> Self {
        let mut p: [u8; 256] = std::array::from_fn(|i| i as u8);
        // Fisher-Yates with an unbiased bounded draw.
        let mut rng = Pcg32::new(seed, 0x6e_6f_69_73_65); // stream "noise" (its ASCII bytes), apart from pixel streams
        for i in (1..256u32).rev() {
            let j = rng.below(i + 1);
            p.swap(i as usize, j as usize);
        }
        let perm = Box::new(std::array::from_fn(|i| p[i & 255]));
        Self { kind, scale, colors, octaves, perm }
    }

    /// Improved noise at `p`, roughly in `[-1, 1]`, zero at integer lattice points.
    pub fn noise(&self, p: Vec3) -> f32 {
        // Wrap the lattice cell into 0..256 in f32 before converting, so huge or non-finite
        // coordinates neither overflow nor index out of bounds (NaN becomes cell 0).
        let f = p.floor();
        let cell = |v: f32| v.rem_euclid(256.0) as usize & 255;
        let (xi, yi, zi) = (cell(f.x), cell(f.y), cell(f.z));
        let d = p - f;
        let (x, y, z) = (d.x, d.y, d.z);
        let (u, v, w) = (fade(x), fade(y), fade(z));
        let h = &self.perm;
        let a = h[xi] as usize + yi;
        let (aa, ab) = (h[a] as usize + zi, h[a + 1] as usize + zi);
        let b = h[xi + 1] as usize + yi;
        let (ba, bb) = (h[b] as usize + zi, h[b + 1] as usize + zi);
        lerp(
            w,
            lerp(
                v,
                lerp(u, grad(h[aa], x, y, z), grad(h[ba], x - 1.0, y, z)),
                lerp(u, grad(h[ab], x, y - 1.0, z), grad(h[bb], x - 1.0, y - 1.0, z)),
            ),
            lerp(
                v,
                lerp(u, grad(h[aa + 1], x, y, z - 1.0), grad(h[ba + 1], x - 1.0, y, z - 1.0)),
                lerp(u, grad(h[ab + 1], x, y - 1.0, z - 1.0), grad(h[bb + 1], x - 1.0, y - 1.0, z - 1.0)),
            ),
        )
    }

    /// The book's turbulence: `|Σ_i noise(2^i p) / 2^i|` over the octaves, in `[0, ~1]`.
    pub fn turbulence(&self, p: Vec3) -> f32 {
        let mut sum = 0.0;
        let mut weight = 1.0;
        let mut q = p;
        for _ in 0..self.octaves.clamp(1, MAX_OCTAVES) {
            sum += weight * self.noise(q);
            weight *= 0.5;
            q *= 2.0;
        }
        sum.abs()
    }

    /// The pattern value at object-space point `p`, in `[0, 1]`.
    pub fn value(&self, p: Vec3) -> f32 {
        let t = match self.kind {
            NoiseKind::Plain => 0.5 * (1.0 + self.noise(self.scale * p)),
            NoiseKind::Turbulence => self.turbulence(self.scale * p),
            NoiseKind::Marble => 0.5 * (1.0 + (self.scale * p.z + 10.0 * self.turbulence(p)).sin()),
            NoiseKind::Wood => {
                let r = (p.x * p.x + p.z * p.z).sqrt();
                0.5 * (1.0 - (TAU * (self.scale * r + self.turbulence(p))).cos())
            }
        };
        // Improved noise peaks slightly above 1 and a NaN point would poison the blend.
        if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) }
    }

    /// Colour at object-space point `p`: the two colours blended by [`Noise::value`].
    #[inline]
    pub fn eval(&self, p: Vec3) -> Rgb {
        self.colors[0].lerp(self.colors[1], self.value(p))
    }
}

/// Perlin's quintic fade `6t^5 - 15t^4 + 10t^3`: C2-continuous across cells, unlike 1985's cubic.
#[inline]
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

#[inline]
fn lerp(t: f32, a: f32, b: f32) -> f32 {
    a + t * (b - a)
}

/// Dot product with one of the 12 cube-edge gradients picked by the low 4 bits of `hash`
/// (the 16 cases repeat four of them), exactly as Perlin's reference `grad`.
#[inline]
fn grad(hash: u8, x: f32, y: f32, z: f32) -> f32 {
    let h = hash & 15;
    let u = if h < 8 { x } else { y };
    let v = if h < 4 {
        y
    } else if h == 12 || h == 14 {
        x
    } else {
        z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points(n: usize) -> impl Iterator<Item = Vec3> {
        let mut rng = Pcg32::new(3, 4);
        (0..n).map(move |_| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0 - 10.0)
    }

    const BW: [Rgb; 2] = [Rgb::ZERO, Rgb::ONE];

    #[test]
    fn deterministic_per_seed_and_seeds_differ() {
        for &kind in NoiseKind::ALL {
            let a = Noise::new(kind, 3.0, BW, 7, 42);
            let b = Noise::new(kind, 3.0, BW, 7, 42);
            let c = Noise::new(kind, 3.0, BW, 7, 43);
            let mut differs = false;
            for p in points(1000) {
                assert_eq!(a.value(p).to_bits(), b.value(p).to_bits());
                differs |= a.value(p) != c.value(p);
            }
            assert!(differs, "{kind}: seeds 42 and 43 give the same texture");
        }
    }

    #[test]
    fn values_in_unit_interval_and_not_constant() {
        for &kind in NoiseKind::ALL {
            let n = Noise::new(kind, 4.0, BW, 7, 1);
            let (mut lo, mut hi) = (f32::MAX, f32::MIN);
            for p in points(20_000) {
                let t = n.value(p);
                assert!((0.0..=1.0).contains(&t), "{kind}: {t} at {p}");
                let c = n.eval(p);
                assert!(c.min_element() >= 0.0 && c.max_element() <= 1.0);
                lo = lo.min(t);
                hi = hi.max(t);
            }
            assert!(hi - lo > 0.5, "{kind}: range only [{lo}, {hi}]");
        }
    }

    #[test]
    fn raw_noise_properties() {
        let n = Noise::new(NoiseKind::Plain, 1.0, BW, 1, 9);
        // Zero on the integer lattice, where every gradient is dotted with a zero offset.
        for p in [Vec3::ZERO, Vec3::new(3.0, -7.0, 100.0), Vec3::new(-1.0, 2.0, 5.0)] {
            assert_eq!(n.noise(p), 0.0);
        }
        // Bounded, with both signs, and continuous.
        let (mut neg, mut pos) = (false, false);
        for p in points(20_000) {
            let v = n.noise(p);
            assert!(v.abs() <= 1.1, "{v}");
            neg |= v < -0.3;
            pos |= v > 0.3;
            assert!((n.noise(p + Vec3::splat(1e-4)) - v).abs() < 1e-2);
        }
        assert!(neg && pos);
        // Period 256 on the lattice, and garbage input stays finite.
        let p = Vec3::new(0.3, 0.6, 0.9);
        assert!((n.noise(p) - n.noise(p + Vec3::new(256.0, 0.0, -512.0))).abs() < 1e-3);
        for &kind in NoiseKind::ALL {
            let n = Noise::new(kind, 1.0, BW, 40, 9);
            for p in [Vec3::splat(f32::NAN), Vec3::new(f32::INFINITY, f32::NEG_INFINITY, 1e30)] {
                assert!((0.0..=1.0).contains(&n.value(p)));
            }
        }
    }

    #[test]
    fn colours_blend_endpoints() {
        let red = Rgb::new(1.0, 0.0, 0.0);
        let blue = Rgb::new(0.0, 0.0, 1.0);
        // Plain noise is 0.5 on the lattice: the mid blend.
        let n = Noise::new(NoiseKind::Plain, 1.0, [red, blue], 1, 5);
        assert_eq!(n.eval(Vec3::ZERO), Rgb::new(0.5, 0.0, 0.5));
    }

    /// The gradient table of Perlin's "Improving Noise" (2002): the 12 cube edges, then
    /// (1,1,0), (−1,1,0), (0,−1,1), (0,−1,−1) again to fill 16.
    const GRADIENTS: [[f64; 3]; 16] = [
        [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [1.0, -1.0, 0.0], [-1.0, -1.0, 0.0],
        [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0], [1.0, 0.0, -1.0], [-1.0, 0.0, -1.0],
        [0.0, 1.0, 1.0], [0.0, -1.0, 1.0], [0.0, 1.0, -1.0], [0.0, -1.0, -1.0],
        [1.0, 1.0, 0.0], [0.0, -1.0, 1.0], [-1.0, 1.0, 0.0], [0.0, -1.0, -1.0],
    ];

    /// Improved noise from its definition, in f64: the sum over the cell's 8 corners c of the
    /// weights Π (fade(d) or 1 − fade(d)) times G[hash(c) mod 16] · (d − c), with
    /// hash(i, j, k) = P[(P[(P[i] + j) mod 256] + k) mod 256] on cell indices mod 256 and
    /// fade(t) = 6t⁵ − 15t⁴ + 10t³. `perm` is the texture's shuffle (only its first 256 entries).
    fn reference_noise(perm: &[u8], p: Vec3) -> f64 {
        let p = [p.x as f64, p.y as f64, p.z as f64];
        let fl = p.map(f64::floor);
        let d = [p[0] - fl[0], p[1] - fl[1], p[2] - fl[2]];
        let cell = fl.map(|f| f.rem_euclid(256.0) as usize);
        let fade = |t: f64| 6.0 * t.powi(5) - 15.0 * t.powi(4) + 10.0 * t.powi(3);
        let w = d.map(fade);
        let hash = |i: usize, j: usize, k: usize| perm[(perm[(perm[i % 256] as usize + j) % 256] as usize + k) % 256] as usize;
        let mut sum = 0.0;
        for c in 0..8 {
            let o = [c & 1, (c >> 1) & 1, (c >> 2) & 1];
            let g = GRADIENTS[hash(cell[0] + o[0], cell[1] + o[1], cell[2] + o[2]) % 16];
            let mut weight = 1.0;
            let mut dot = 0.0;
            for a in 0..3 {
                weight *= if o[a] == 1 { w[a] } else { 1.0 - w[a] };
                dot += g[a] * (d[a] - o[a] as f64);
            }
            sum += weight * dot;
        }
        sum
    }

    /// The book's turbulence from its definition: |Σ_{i < octaves} noise(2^i p) / 2^i|, the
    /// octaves read as 1..=16.
    fn reference_turbulence(perm: &[u8], p: Vec3, octaves: u32) -> f64 {
        let octaves = octaves.clamp(1, 16) as i32;
        (0..octaves).map(|i| reference_noise(perm, p * 2f32.powi(i)) / 2f64.powi(i)).sum::<f64>().abs()
    }

    #[test]
    fn the_shuffle_is_a_permutation_stored_twice() {
        for seed in [0, 1, 9, 42] {
            let n = Noise::new(NoiseKind::Plain, 1.0, BW, 1, seed);
            let mut seen = [false; 256];
            for &v in &n.perm[..256] {
                assert!(!seen[v as usize], "seed {seed}: {v} twice");
                seen[v as usize] = true;
            }
            assert_eq!(n.perm[..256], n.perm[256..]);
        }
    }

    #[test]
    fn grad_is_perlins_gradient_table() {
        // (1, 10, 100) · G names the gradient: each of the 16 entries, and the hash's high bits ignored.
        for h in 0..=255u8 {
            let g = GRADIENTS[(h % 16) as usize];
            let want = g[0] + 10.0 * g[1] + 100.0 * g[2];
            assert_eq!(grad(h, 1.0, 10.0, 100.0) as f64, want, "hash {h}");
        }
    }

    #[test]
    fn fade_and_lerp_by_hand() {
        // 6t⁵ − 15t⁴ + 10t³: 0 and 1 at the ends, ½ in the middle, 0.103515625 at ¼
        // (6/1024 − 15/256 + 10/64), 0.896484375 at ¾ (by symmetry, 1 − that).
        assert_eq!(fade(0.0), 0.0);
        assert_eq!(fade(1.0), 1.0);
        assert_eq!(fade(0.5), 0.5);
        assert_eq!(fade(0.25), 53.0 / 512.0); // 0.103515625
        assert_eq!(fade(0.75), 459.0 / 512.0); // 0.896484375
        assert_eq!(lerp(0.25, 2.0, 6.0), 3.0);
        assert_eq!(lerp(0.0, 2.0, 6.0), 2.0);
        assert_eq!(lerp(1.0, 2.0, 6.0), 6.0);
    }

    #[test]
    fn noise_of_the_identity_permutation_by_hand() {
        // With P[i] = i, hash(i, j, k) = i + j + k. At (½, ½, ½) every weight is ⅛ and the
        // offsets d − c are (±½, ±½, ±½); the corners (0,0,0) .. (1,1,1) give, with
        // G0 = (1,1,0), G1 = (−1,1,0), G2 = (1,−1,0), G3 = (−1,−1,0):
        // (0,0,0) G0·(½,½,½) = 1; (1,0,0) G1·(−½,½,½) = 1; (0,1,0) G1·(½,−½,½) = −1;
        // (0,0,1) G1·(½,½,−½) = 0; (1,1,0) G2·(−½,−½,½) = 0; (1,0,1) G2·(−½,½,−½) = −1;
        // (0,1,1) G2·(½,−½,−½) = 1; (1,1,1) G3·(−½,−½,−½) = 1: sum 2, noise 2/8 = ¼.
        let n = Noise { perm: Box::new(std::array::from_fn(|i| (i & 255) as u8)), ..Noise::new(NoiseKind::Plain, 1.0, BW, 1, 0) };
        assert!((n.noise(Vec3::splat(0.5)) - 0.25).abs() < 1e-7);
        // One cell over in x, (1.5, ½, ½), the hashes are one more, G1 .. G4 with G4 = (1,0,1):
        // (0,0,0) G1·(½,½,½) = 0; (1,0,0) G2·(−½,½,½) = −1;
        // (0,1,0) G2·(½,−½,½) = 1; (0,0,1) G2·(½,½,−½) = 0; (1,1,0) G3·(−½,−½,½) = 1;
        // (1,0,1) G3·(−½,½,−½) = 0; (0,1,1) G3·(½,−½,−½) = 0; (1,1,1) G4·(−½,−½,−½) = −1: sum 0.
        assert!(n.noise(Vec3::new(1.5, 0.5, 0.5)).abs() < 1e-7);
        // Along an edge, (¼, 0, 0): only the corners (0,0,0) and (1,0,0) weigh, 1 − fade(¼) and
        // fade(¼): G0·(¼,0,0) = ¼ and G1·(−¾,0,0) = ¾, so ¼ + 0.103515625·(¾ − ¼) = 0.3017578125.
        assert!((n.noise(Vec3::new(0.25, 0.0, 0.0)) - 309.0 / 1024.0).abs() < 1e-7); // 0.3017578125
        // (0, ¼, 0): corners (0,0,0) G0·(0,¼,0) = ¼ and (0,1,0) G1·(0,−¾,0) = −¾:
        // ¼ + 0.103515625·(−1) = 0.146484375.
        assert!((n.noise(Vec3::new(0.0, 0.25, 0.0)) - 75.0 / 512.0).abs() < 1e-7); // 0.146484375
        // (0, 0, ¼): G0·(0,0,¼) = 0 and G1·(0,0,−¾) = 0: zero along z from this corner.
        assert!(n.noise(Vec3::new(0.0, 0.0, 0.25)).abs() < 1e-7);
    }

    #[test]
    fn noise_matches_perlins_definition_written_out() {
        let n = Noise::new(NoiseKind::Plain, 1.0, BW, 1, 9);
        let mut rng = Pcg32::new(11, 12);
        for i in 0..4000 {
            // Negative cells and cells past 256, where the indices wrap.
            let span = if i < 2000 { 20.0 } else { 1200.0 };
            let p = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * span;
            let want = reference_noise(&n.perm[..], p);
            assert!((n.noise(p) as f64 - want).abs() < 1e-5, "{p}: {} against {want}", n.noise(p));
        }
    }

    #[test]
    fn turbulence_and_patterns_match_their_definitions() {
        let mut rng = Pcg32::new(5, 6);
        let pts: Vec<Vec3> = (0..300).map(|_| (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 8.0).collect();
        // Octaves 0 and 1 are one octave, 40 is 16.
        for octaves in [0, 1, 3, 7, 40] {
            let n = Noise::new(NoiseKind::Turbulence, 3.0, BW, octaves, 21);
            let perm = &n.perm[..];
            for &p in &pts {
                let turb = reference_turbulence(perm, p, octaves);
                assert!((n.turbulence(p) as f64 - turb).abs() < 2e-5, "{octaves} octaves at {p}");
            }
        }
        let clamp = |t: f64| t.clamp(0.0, 1.0);
        for &kind in NoiseKind::ALL {
            let n = Noise::new(kind, 3.0, BW, 5, 21);
            let perm = &n.perm[..];
            for &p in &pts {
                let r = ((p.x as f64).powi(2) + (p.z as f64).powi(2)).sqrt();
                let turb = reference_turbulence(perm, p, 5);
                let (want, tol) = match kind {
                    NoiseKind::Plain => (clamp(0.5 * (1.0 + reference_noise(perm, p * 3.0))), 1e-5),
                    NoiseKind::Turbulence => (clamp(reference_turbulence(perm, p * 3.0, 5)), 2e-5),
                    NoiseKind::Marble => (0.5 * (1.0 + (3.0 * p.z as f64 + 10.0 * turb).sin()), 2e-4),
                    NoiseKind::Wood => (0.5 * (1.0 - (std::f64::consts::TAU * (3.0 * r + turb)).cos()), 2e-4),
                };
                let got = n.value(p) as f64;
                assert!((got - want).abs() < tol, "{kind} at {p}: {got} against {want}");
            }
        }
        // The colour is the blend of the two at the value: 0.3 of the way from (1,0,0) to (0,0,1)
        // where the pattern is 0.3.
        let red = Rgb::new(1.0, 0.0, 0.0);
        let blue = Rgb::new(0.0, 0.0, 1.0);
        let n = Noise::new(NoiseKind::Plain, 3.0, [red, blue], 1, 21);
        for &p in &pts[..20] {
            let t = n.value(p);
            assert!((n.eval(p) - Rgb::new(1.0 - t, 0.0, t)).abs().max_element() < 1e-6);
        }
    }

    #[test]
    fn names_parse() {
        for &k in NoiseKind::ALL {
            assert_eq!(k.name().parse(), Ok(k));
        }
        assert_eq!(
            "fbm".parse::<NoiseKind>().unwrap_err(),
            "unknown noise kind `fbm` (valid: plain, turbulence, marble, wood)"
        );
    }
}
