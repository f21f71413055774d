use glam::Vec3;

/// `γₙ = nε / (1 - nε)`, the bound on the relative error of `n` chained floating-point
/// operations (Higham 2002; pbrt-v4 §6.8.1), with `ε` half an ulp of 1.
pub const fn gamma(n: u32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// Moves a surface point off the surface along the geometric normal `n`, to the side of
/// `dir`, so that a ray leaving it cannot hit the same surface again (self-intersection
/// "acne") nor start behind it (light leaks).
///
/// `p_error` is a conservative bound on the absolute error of each coordinate of `p`, which
/// the shape computes alongside the point (pbrt-v4 §6.8.6). The point moves by the
/// projection of that error box onto the normal, then one more ulp away, so the offset is
/// as small as is safe *at any scale*. (Wächter & Binder's fixed-ulp offset, Ray Tracing
/// Gems ch. 6, was tried first: its absolute offset near the origin, tuned for scenes of unit
/// size, leaked light at the contact of a sphere and a plane once the scene was scaled by
/// 1e-3.)
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, dir: Vec3) -> Vec3 {
    let n = if dir.dot(n) < 0.0 { -n } else { n };
    let d = n.abs().dot(p_error);
    let mut po = (p + d * n).to_array();
    let o = n.to_array();
    for k in 0..3 {
        if o[k] > 0.0 {
            po[k] = po[k].next_up();
        } else if o[k] < 0.0 {
            po[k] = po[k].next_down();
        }
    }
    Vec3::from_array(po)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_side_of_the_direction_at_every_scale() {
        for scale in [1e-3f32, 1.0, 1e3, 1e5] {
            let p = Vec3::new(0.7, -0.3, 0.2) * scale;
            let err = gamma(7) * p.abs();
            let n = Vec3::Y;
            let up = offset_ray_origin(p, err, n, Vec3::new(0.0, 1.0, 0.0));
            let down = offset_ray_origin(p, err, n, Vec3::new(0.0, -1.0, 0.0));
            assert!(up.y > p.y + err.y && down.y < p.y - err.y, "scale {scale}");
            // The displacement is a few ulps of the coordinates, not a fixed epsilon.
            assert!((up - p).length() <= 1e-5 * scale, "scale {scale}: {}", (up - p).length());
        }
        // A zero error bound still moves the point by one ulp.
        let p = Vec3::new(1.0, 1.0, 1.0);
        assert!(offset_ray_origin(p, Vec3::ZERO, Vec3::Y, Vec3::Y).y > 1.0);
    }
}
