use glam::Vec3;

/// Moves a surface point off the surface along the geometric normal `n`, to the side of `dir`,
/// so that a ray leaving it does not hit the same surface again (self-intersection "acne").
///
/// Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing
/// Gems (2019), ch. 6: the offset is a fixed number of ulps of the point's coordinates, added
/// in integer space, plus a tiny absolute offset near the origin. It scales with the magnitude
/// of the coordinates, so scenes at 1e-3 and at 1e3 behave alike, unlike a fixed epsilon.
pub fn offset_ray_origin(p: Vec3, n: Vec3, dir: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let n = if n.dot(dir) < 0.0 { -n } else { n };
    let of_i = (INT_SCALE * n).to_array().map(|v| v as i32);
    let pa = p.to_array();
    let mut p_i = [0.0f32; 3];
    for k in 0..3 {
        let bits = pa[k].to_bits() as i32;
        let delta = if pa[k] < 0.0 { -of_i[k] } else { of_i[k] };
        p_i[k] = f32::from_bits(bits.wrapping_add(delta) as u32);
    }
    let na = n.to_array();
    let mut out = [0.0f32; 3];
    for k in 0..3 {
        out[k] = if pa[k].abs() < ORIGIN { pa[k] + FLOAT_SCALE * na[k] } else { p_i[k] };
    }
    Vec3::from_array(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_side_of_the_direction() {
        for scale in [1e-3f32, 1.0, 1e3, 1e5] {
            let p = Vec3::new(0.7, -0.3, 0.2) * scale;
            let n = Vec3::Y;
            let up = offset_ray_origin(p, n, Vec3::new(0.0, 1.0, 0.0));
            let down = offset_ray_origin(p, n, Vec3::new(0.0, -1.0, 0.0));
            assert!(up.y > p.y && down.y < p.y, "scale {scale}");
            // Relative displacement stays tiny at every scale.
            assert!((up - p).length() <= 1e-4 * scale.max(1.0));
        }
    }
}
