//! Where in a pixel each sample goes (anti-aliasing).

use std::fmt;
use std::str::FromStr;

use raylab_core::{sampling, Pcg32, Vec2};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    /// Independent uniform positions.
    Random,
    /// One position per cell of an `n × n` grid (`spp = n²`): stratified, less noise.
    Jittered,
}

impl SamplerKind {
    pub const ALL: &'static [SamplerKind] = &[SamplerKind::Random, SamplerKind::Jittered];

    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Random => "random",
            SamplerKind::Jittered => "jittered",
        }
    }

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

    /// Position of sample `i` of `spp` within the pixel, in `[0,1)²`.
    #[inline]
    pub fn pixel_offset(self, i: u32, spp: u32, rng: &mut Pcg32) -> Vec2 {
        match self {
            SamplerKind::Random => rng.next_vec2(),
            SamplerKind::Jittered => {
                let n = (spp as f32).sqrt().round() as u32;
                sampling::jittered(i, n.max(1), rng.next_vec2())
            }
        }
    }
}

impl fmt::Display for SamplerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SamplerKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.iter().copied().find(|k| k.name() == s).ok_or_else(|| format!("unknown sampler `{s}` (valid: random, jittered)"))
    }
}
