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
        let mut rng = Pcg32::new(seed, 0x6e6f_6973_65); // stream "noise", apart from pixel streams
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
