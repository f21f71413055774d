//! Textures: colour as a function of surface parameters `uv` and object-space position `p`.
//!
//! As in pbrt-v4's `textures.h`, a texture is a closed sum type evaluated by a `match`, so a
//! material's lookup is a jump, not a virtual call. Image textures are 2D (`uv`); checkers are
//! either; noise is a solid texture (`p`), so it never stretches over a bad parameterisation.
//!
//! Conventions, shared with the loader and the camera's background:
//! - `uv` has its origin at the bottom-left of an image and `v` grows upwards (OBJ, pbrt);
//! - image texels are stored row-major with row 0 at the *top* (the order of every file format);
//! - directions map to an equirectangular (latitude-longitude) image by [`equirect_uv`], `y` up.

mod checker;
mod image;
mod noise;

pub use checker::{Checker, CheckerSpace};
pub use image::{Filter, ImageTexture, Wrap};
pub use noise::{Noise, NoiseKind};

use std::f32::consts::{FRAC_1_PI, PI, TAU};

use raylab_core::{Rgb, Vec2, Vec3};

/// A colour source for materials and lights.
#[derive(Clone, Debug)]
pub enum Texture {
    /// The same colour everywhere.
    Constant(Rgb),
    /// A bitmap looked up at `uv`.
    Image(ImageTexture),
    /// Two alternating colours, in `uv` or in space.
    Checker(Checker),
    /// Seeded Perlin noise on the object-space point.
    Noise(Noise),
}

impl Texture {
    /// Colour at surface parameters `uv` and object-space point `p` (for solid textures).
    #[inline]
    pub fn eval(&self, uv: Vec2, p: Vec3) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::Image(t) => t.lookup(uv),
            Texture::Checker(t) => t.eval(uv, p),
            Texture::Noise(t) => t.eval(p),
        }
    }
}

/// Direction to equirectangular `uv`, `y` up:
/// `u = 0.5 + atan2(d.z, d.x) / 2π`, `v = 0.5 + asin(d.y) / π`.
///
/// So `+x` is the centre of the image (`u = 0.5`), `+z` is `u = 0.75`, `-z` is `u = 0.25`, the
/// seam `u = 0 | 1` is `-x`, `+y` is the top row (`v = 1`) and `-y` the bottom (`v = 0`).
/// The sign of `z` is chosen for maps seen from *inside* (backgrounds, environment lights):
/// with a right-handed camera looking along `+x`, turning right (towards `+z`) moves right in
/// the image, so a photographed panorama is not mirrored. A sphere seen from outside needs the
/// opposite sense; use [`sphere_uv`] for it.
///
/// `dir` need not be normalised; the zero vector maps to the centre `(0.5, 0.5)`.
#[inline]
pub fn equirect_uv(dir: Vec3) -> Vec2 {
    let d = dir.normalize_or_zero();
    // Clamp: normalisation can leave |y| a hair above 1, where asin is NaN.
    Vec2::new(0.5 + d.z.atan2(d.x) / TAU, 0.5 + d.y.clamp(-1.0, 1.0).asin() * FRAC_1_PI)
}

/// The inverse of [`equirect_uv`]: the unit direction at the centre of `uv`.
#[inline]
pub fn equirect_dir(uv: Vec2) -> Vec3 {
    let phi = (uv.x - 0.5) * TAU;
    let lat = (uv.y - 0.5) * PI;
    let (sin_lat, cos_lat) = lat.sin_cos();
    let (sin_phi, cos_phi) = phi.sin_cos();
    Vec3::new(cos_lat * cos_phi, sin_lat, cos_lat * sin_phi)
}

/// `uv` of a point on a sphere from its outward normal `n`, for textures seen from outside
/// (a globe): the latitude-longitude map of [`equirect_uv`] with `u` running the other way, so
/// the image is not mirrored when the camera looks at the sphere. This is the convention of
/// *Ray Tracing: The Next Week* (`get_sphere_uv`): `+x -> (0.5, 0.5)`, `+z -> (0.25, 0.5)`.
#[inline]
pub fn sphere_uv(n: Vec3) -> Vec2 {
    equirect_uv(Vec3::new(n.x, n.y, -n.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec2, b: Vec2) -> bool {
        (a - b).abs().max_element() < 1e-6
    }

    #[test]
    fn equirect_known_directions() {
        assert!(close(equirect_uv(Vec3::X), Vec2::new(0.5, 0.5)));
        assert!(close(equirect_uv(Vec3::Z), Vec2::new(0.75, 0.5)));
        assert!(close(equirect_uv(-Vec3::Z), Vec2::new(0.25, 0.5)));
        assert_eq!(equirect_uv(Vec3::Y).y, 1.0);
        assert_eq!(equirect_uv(-Vec3::Y).y, 0.0);
        // -x lies on the seam: u is 0 or 1 depending on the sign of z's zero.
        let u = equirect_uv(-Vec3::X).x;
        assert!(u.abs() < 1e-6 || (u - 1.0).abs() < 1e-6, "u = {u}");
        // Not normalised, and degenerate.
        assert!(close(equirect_uv(Vec3::new(0.0, 0.0, 7.0)), Vec2::new(0.75, 0.5)));
        assert!(close(equirect_uv(Vec3::ZERO), Vec2::new(0.5, 0.5)));
    }

    #[test]
    fn equirect_round_trip() {
        let mut rng = raylab_core::Pcg32::new(7, 1);
        for _ in 0..10_000 {
            // Stay off the poles, where u is undefined.
            let uv = Vec2::new(rng.next_f32(), 0.001 + 0.998 * rng.next_f32());
            let d = equirect_dir(uv);
            assert!((d.length() - 1.0).abs() < 1e-5);
            let back = equirect_uv(d);
            // u may come back as u - 1 or u + 1 on the seam.
            let du = (back.x - uv.x).abs();
            assert!(du.min((du - 1.0).abs()) < 1e-4 && (back.y - uv.y).abs() < 1e-4, "{uv} -> {back}");
            assert!((equirect_dir(back) - d).length() < 1e-4);
        }
        assert!((equirect_dir(Vec2::new(0.3, 1.0)) - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn sphere_uv_matches_ray_tracing_the_next_week() {
        // The table printed in the book, section "Texture Coordinates for Spheres".
        assert!(close(sphere_uv(Vec3::X), Vec2::new(0.5, 0.5)));
        assert!(close(sphere_uv(Vec3::Y), Vec2::new(0.5, 1.0)));
        // Written with +0 components: `-Vec3::Y` has x = -0, which puts the pole on the seam.
        assert!(close(sphere_uv(Vec3::new(0.0, -1.0, 0.0)), Vec2::new(0.5, 0.0)));
        assert!(close(sphere_uv(Vec3::Z), Vec2::new(0.25, 0.5)));
        assert!(close(sphere_uv(-Vec3::Z), Vec2::new(0.75, 0.5)));
    }

    #[test]
    fn texture_dispatch() {
        let c = Rgb::new(0.1, 0.2, 0.3);
        assert_eq!(Texture::Constant(c).eval(Vec2::ZERO, Vec3::ZERO), c);
        let img = ImageTexture::new(1, 1, vec![c], Wrap::Repeat, Filter::Nearest).unwrap();
        assert_eq!(Texture::Image(img).eval(Vec2::new(3.3, -2.1), Vec3::ZERO), c);
        let checker = Checker { even: Rgb::ONE, odd: Rgb::ZERO, scale: 1.0, space: CheckerSpace::Solid };
        assert_eq!(Texture::Checker(checker).eval(Vec2::ZERO, Vec3::splat(0.5)), Rgb::ONE);
    }
}
