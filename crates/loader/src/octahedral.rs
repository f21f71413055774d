//! pbrt-v4's environment maps: equal-area octahedral squares (Clarberg 2008, pbrt-v4's
//! `EqualAreaSquareToSphere` / `EqualAreaSphereToSquare`, `util/math.cpp`), converted to
//! raylab's equirectangular maps by resampling.

use raylab_core::{Rgb, Vec2, Vec3};
use raylab_render::texture::equirect_dir;

/// The unit direction of a point of the unit square: the square's centre is +z, its
/// corners -z, the diamond between the edge midpoints the equator.
pub fn square_to_sphere(p: Vec2) -> Vec3 {
    let (u, v) = (2.0 * p.x - 1.0, 2.0 * p.y - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    // Signed distance from the diagonal: positive inside the diamond (northern hemisphere).
    let signed = 1.0 - (up + vp);
    let r = 1.0 - signed.abs();
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * std::f32::consts::FRAC_PI_4;
    let z = (1.0 - r * r).copysign(signed);
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    Vec3::new(phi.cos().copysign(u) * s, phi.sin().copysign(v) * s, z)
}

/// The inverse of [`square_to_sphere`], for a unit direction.
pub fn sphere_to_square(d: Vec3) -> Vec2 {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let (a, b) = (x.max(y), x.min(y));
    let b = if a == 0.0 { 0.0 } else { b / a };
    let mut phi = b.atan() * std::f32::consts::FRAC_2_PI;
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        (u, v) = (1.0 - v, 1.0 - u);
    }
    Vec2::new(0.5 * (u.copysign(d.x) + 1.0), 0.5 * (v.copysign(d.y) + 1.0))
}

/// Resamples a `side × side` equal-area map (row 0 at the top, pbrt's image order) into a
/// `2·side × side` equirectangular one in raylab's convention (row 0 at the top, `+y` up),
/// bilinearly; `to_light` takes a world direction into the map's (light) space.
pub fn to_equirect(side: u32, texels: &[Rgb], to_light: impl Fn(Vec3) -> Vec3) -> (u32, u32, Vec<Rgb>) {
    let (w, h) = (2 * side, side);
    let n = side as f32;
    let at = |x: i64, y: i64| texels[(y.clamp(0, side as i64 - 1) * side as i64 + x.clamp(0, side as i64 - 1)) as usize];
    let out = (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| {
            // Texel centres; raylab's v runs up, rows down.
            let dir = equirect_dir(Vec2::new((i as f32 + 0.5) / w as f32, 1.0 - (j as f32 + 0.5) / h as f32));
            let p = sphere_to_square(to_light(dir).normalize()) * n - Vec2::splat(0.5);
            let (x0, y0) = (p.x.floor(), p.y.floor());
            let (fx, fy) = (p.x - x0, p.y - y0);
            let (x0, y0) = (x0 as i64, y0 as i64);
            (at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx) * (1.0 - fy) + (at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx) * fy
        })
        .collect();
    (w, h, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_two_mappings_are_inverses_and_place_the_poles() {
        assert!((square_to_sphere(Vec2::splat(0.5)) - Vec3::Z).length() < 1e-6);
        for corner in [Vec2::ZERO, Vec2::ONE, Vec2::new(0.0, 1.0)] {
            assert!((square_to_sphere(corner) + Vec3::Z).length() < 1e-6, "{corner}");
        }
        // The edge midpoints and the diamond are the equator.
        assert!(square_to_sphere(Vec2::new(1.0, 0.5)).abs_diff_eq(Vec3::X, 1e-6));
        assert!(square_to_sphere(Vec2::new(0.25, 0.25)).z.abs() < 1e-6);
        for i in 0..64 {
            for j in 0..64 {
                let p = Vec2::new((i as f32 + 0.5) / 64.0, (j as f32 + 0.5) / 64.0);
                let d = square_to_sphere(p);
                assert!((d.length() - 1.0).abs() < 1e-5, "{p}: |d| = {}", d.length());
                assert!((sphere_to_square(d) - p).length() < 1e-5, "{p} -> {d} -> {}", sphere_to_square(d));
            }
        }
    }

    #[test]
    fn equal_areas_of_the_square_are_equal_solid_angles() {
        // The fraction of a uniform grid over the square above z = c is (1 - c) / 2, the
        // solid-angle fraction of that cap.
        let n = 400;
        for c in [-0.5f32, 0.0, 0.3, 0.8] {
            let above = (0..n * n).filter(|k| square_to_sphere(Vec2::new((k % n) as f32 + 0.5, (k / n) as f32 + 0.5) / n as f32).z > c).count();
            let fraction = above as f32 / (n * n) as f32;
            assert!((fraction - (1.0 - c) / 2.0).abs() < 2e-3, "cap above {c}: {fraction}");
        }
    }

    #[test]
    fn resampling_keeps_each_hemisphere_where_it_was() {
        // The map is red where z > 0 (the diamond) and blue elsewhere; with light space the
        // world's (no transform), the equirect map is red above the equator (rows 0..h/2).
        let side = 64;
        let texels: Vec<Rgb> = (0..side * side).map(|k| if square_to_sphere(Vec2::new((k % side) as f32 + 0.5, (k / side) as f32 + 0.5) / side as f32).z > 0.0 { Rgb::X } else { Rgb::Z }).collect();
        let (w, h, out) = to_equirect(side, &texels, |d| Vec3::new(d.x, d.z, d.y));
        assert_eq!((w, h), (128, 64));
        // The light's +z is the world's +y here: the top rows are red, the bottom blue.
        assert!(out[..w as usize * 8].iter().all(|c| *c == Rgb::X));
        assert!(out[(h as usize - 8) * w as usize..].iter().all(|c| *c == Rgb::Z));
    }
}
