//! Colour helpers: luminance and the sRGB transfer function.

use crate::Rgb;

/// Rec. 709 luminance of linear RGB.
pub fn luminance(c: Rgb) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// sRGB-encoded value in [0,1] to linear.
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
}

/// Linear value to sRGB encoding, clamped to [0,1].
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.0031308 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 }
}

/// Linear value to an 8-bit sRGB code.
pub fn linear_to_srgb8(v: f32) -> u8 {
    (linear_to_srgb(v) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip() {
        for i in 0..=255u32 {
            let v = i as f32 / 255.0;
            assert_eq!(linear_to_srgb8(srgb_to_linear(v)), i as u8);
        }
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
    }
}
