use std::fmt;
use std::str::FromStr;

use raylab_core::{Rgb, Vec3};

/// The space a normal map's vectors are expressed in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NormalSpace {
    /// Relative to the surface: x along the tangent (+u), y along the bitangent, z along the
    /// shading normal (the OpenGL "+Y up" convention, as MikkTSpace bakers write).
    #[default]
    Tangent,
    /// The shape's own coordinates before its transform.
    Object,
}

impl NormalSpace {
    pub const ALL: [NormalSpace; 2] = [NormalSpace::Tangent, NormalSpace::Object];

    pub fn name(self) -> &'static str {
        match self {
            NormalSpace::Tangent => "tangent",
            NormalSpace::Object => "object",
        }
    }
}

impl FromStr for NormalSpace {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        NormalSpace::ALL.into_iter().find(|n| n.name() == s).ok_or_else(|| format!("unknown normal space `{s}` (valid: {})", NormalSpace::ALL.map(NormalSpace::name).join(", ")))
    }
}

impl fmt::Display for NormalSpace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A texel `c` in `[0, 1]³` (linear, never sRGB-decoded) to the unit normal `2c − 1`,
/// renormalised because filtering and 8-bit storage shorten it. A black texel gives `+z`.
pub fn decode_normal(c: Rgb) -> Vec3 {
    (2.0 * c - Vec3::ONE).try_normalize().unwrap_or(Vec3::Z)
}

/// The inverse of [`decode_normal`] for a unit normal.
pub fn encode_normal(n: Vec3) -> Rgb {
    0.5 * (n + Vec3::ONE)
}
