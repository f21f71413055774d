//! A furry ball (not an SPD scene): `strands` wavy, drooping strands rooted evenly over a
//! unit sphere, each a Catmull–Rom curve of `segments` cubic segments, tapering to a
//! third of its root radius (written to a curve file by `raylab gen`), for scaling curves of
//! curve intersection against strand count.

use std::f32::consts::PI;

use raylab_core::{Frame, Pcg32, Rgb, Vec3, Vec4};
use raylab_render::shape::curve::{to_bezier_segments, Basis};
use raylab_render::shape::Curve;
use raylab_render::Material;

use crate::{base, sphere, Generated};

const LENGTH: f32 = 0.6;

pub(crate) fn hair(strands: u32, segments: u32) -> Result<Generated, String> {
    if !(1..=1_000_000).contains(&strands) {
        return Err(format!("--strands must be between 1 and 1000000, found {strands}"));
    }
    if !(1..=64).contains(&segments) {
        return Err(format!("--segments must be between 1 and 64, found {segments}"));
    }
    // Thinner strands as they get denser, so that the ball stays furry, not solid.
    let root_radius = (0.25 / (strands as f32).sqrt()).clamp(0.001, 0.02);
    let step = LENGTH / segments as f32;
    let golden = PI * (3.0 - 5.0f32.sqrt());
    let mut rng = Pcg32::new(2018, strands as u64);
    let (mut g, p) = base(&format!("Furry ball: {strands} strands, {segments} curve segments each"), Vec3::new(0.0, 0.9, 4.6), Vec3::new(0.0, -0.1, 0.0), 40.0);
    let hair = g.scene.add_material("hair", Material::Hair { color: Rgb::new(0.55, 0.33, 0.15).into(), kd: 0.7, ks: 0.25, exponent: 60.0 });
    sphere(&mut g.scene, Vec3::ZERO, 1.0, p.b);
    for k in 0..strands {
        // Fibonacci lattice: evenly spread roots.
        let y = 1.0 - 2.0 * (k as f32 + 0.5) / strands as f32;
        let ring = (1.0 - y * y).max(0.0).sqrt();
        let theta = golden * k as f32;
        let n = Vec3::new(ring * theta.cos(), y, ring * theta.sin());
        let side = Frame::from_z(n);
        let (phase, wave) = (2.0 * PI * rng.next_f32(), 0.3 + 0.4 * rng.next_f32());
        // A phantom point inside the ball, so that the spline starts at the root.
        let mut q = n - step * n;
        let mut points = Vec::with_capacity(segments as usize + 3);
        for j in 0..segments + 3 {
            let along = j.saturating_sub(1) as f32 / segments as f32;
            let radius = root_radius * (1.0 - 0.67 * along.min(1.0));
            points.push(Vec4::new(q.x, q.y, q.z, radius));
            let a = phase + 2.5 * j as f32;
            let dir = n - 1.2 * along * Vec3::Y + wave * (a.sin() * side.x + a.cos() * side.y);
            q += step * dir.normalize();
        }
        // A Catmull–Rom spline through the points, as Bézier segments (what the loader makes of
        // a `basis = "catmull-rom"` curve).
        g.scene.geometry.add_curve(Curve::new(to_bezier_segments(Basis::CatmullRom, 3, &points)?, hair));
    }
    Ok(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strands_and_segments_are_counted() {
        let g = hair(50, 4).unwrap();
        assert_eq!(g.scene.geometry.curves.len(), 50);
        assert_eq!(g.curve_segments(), 200);
        assert_eq!(g.scene.geometry.spheres.len(), 1);
        assert_eq!(hair(0, 4).err().unwrap(), "--strands must be between 1 and 1000000, found 0");
        assert_eq!(hair(10, 65).err().unwrap(), "--segments must be between 1 and 64, found 65");
    }
}
