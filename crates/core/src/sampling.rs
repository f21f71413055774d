//! Warps from the unit square to common domains, each with its density.

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

/// Concentric map of the square onto the unit disk (Shirley & Chiu 1997): low distortion,
/// so stratification survives the warp.
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() { (o.x, FRAC_PI_4 * (o.y / o.x)) } else { (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y)) };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Cosine-weighted direction about +z (Malley's method); pdf = cos θ / π.
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Uniform direction on the unit sphere; pdf = 1 / 4π.
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Uniform barycentrics `(b0, b1)` on a triangle (Heitz 2019, low-distortion map).
pub fn uniform_triangle(u: Vec2) -> (f32, f32) {
    let (b0, b1);
    if u.x < u.y {
        b0 = u.x / 2.0;
        b1 = u.y - b0;
    } else {
        b1 = u.y / 2.0;
        b0 = u.x - b1;
    }
    (b0, b1)
}

/// Sample `i` of an `n × n` jittered (stratified) pattern: cell `i`, random offset `u` inside.
pub fn jittered(i: u32, n: u32, u: Vec2) -> Vec2 {
    let (cx, cy) = (i % n, i / n);
    (Vec2::new(cx as f32, cy as f32) + u) / n as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warps_land_in_their_domains() {
        let mut r = crate::Pcg32::new(3, 4);
        for _ in 0..10_000 {
            let u = r.next_vec2();
            assert!(concentric_disk(u).length() <= 1.0 + 1e-6);
            let c = cosine_hemisphere(u);
            assert!(c.z >= 0.0 && (c.length() - 1.0).abs() < 1e-4);
            assert!((uniform_sphere(u).length() - 1.0).abs() < 1e-4);
            let (b0, b1) = uniform_triangle(u);
            assert!(b0 >= 0.0 && b1 >= 0.0 && b0 + b1 <= 1.0 + 1e-6);
        }
    }

    #[test]
    fn jittered_cells_cover_the_square_once() {
        let n = 4;
        let mut seen = [false; 16];
        for i in 0..16 {
            let p = jittered(i, n, Vec2::splat(0.5));
            let cell = (p.y * 4.0) as usize * 4 + (p.x * 4.0) as usize;
            assert!(!seen[cell]);
            seen[cell] = true;
        }
    }
}
