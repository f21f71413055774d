
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

raylab_core::named_enum!(NormalSpace, "normal space", {
    Tangent => "tangent",
    Object => "object",
});

/// A texel `c` in `[0, 1]³` (linear, never sRGB-decoded) to the unit normal `2c − 1`,
/// renormalised because filtering and 8-bit storage shorten it. A mid-grey texel (½, ½, ½),
/// the zero vector, gives `+z` (a black one gives (−1, −1, −1)/√3, below the surface).
pub fn decode_normal(c: Rgb) -> Vec3 {
    (2.0 * c - Vec3::ONE).try_normalize().unwrap_or(Vec3::Z)
}

/// The inverse of [`decode_normal`] for a unit normal.
pub fn encode_normal(n: Vec3) -> Rgb {
    0.5 * (n + Vec3::ONE)
}
