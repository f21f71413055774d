use raylab_core::{sampling, Ray, Vec2, Vec3};

/// A perspective camera from look-from / look-at / up and a vertical field of view, with an
/// optional thin lens for depth of field.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub from: Vec3,
    pub at: Vec3,
    pub up: Vec3,
    /// Full vertical field of view in degrees.
    pub vfov: f32,
    /// Lens diameter; 0 = pinhole.
    pub aperture: f32,
    pub focus_distance: f32,
    // Derived: the image plane at `focus_distance`, spanned by `horizontal` and `vertical`
    // from its top-left corner.
    top_left: Vec3,
    horizontal: Vec3,
    vertical: Vec3,
    u: Vec3,
    v: Vec3,
}

impl Camera {
    /// `focus_distance = None` focuses on `at`. Errors name the offending parameter.
    pub fn new(from: Vec3, at: Vec3, up: Vec3, vfov: f32, aspect: f32, aperture: f32, focus_distance: Option<f32>) -> Result<Self, String> {
        let w = (from - at).try_normalize().ok_or("camera.at: must differ from camera.from")?;
        let u = up.cross(w).try_normalize().ok_or("camera.up: must not be parallel to the viewing direction")?;
        let v = w.cross(u);
        let focus = focus_distance.unwrap_or((from - at).length());
        let half_h = (vfov.to_radians() / 2.0).tan() * focus;
        let half_w = aspect * half_h;
        let horizontal = 2.0 * half_w * u;
        let vertical = -2.0 * half_h * v;
        let top_left = from - focus * w - half_w * u + half_h * v;
        Ok(Self { from, at, up, vfov, aperture, focus_distance: focus, top_left, horizontal, vertical, u, v })
    }

    /// The ray through film position `film` (`(0,0)` top-left, `(1,1)` bottom-right), with
    /// `lens` a point of the unit square for the thin lens.
    #[inline]
    pub fn ray(&self, film: Vec2, lens: Vec2) -> Ray {
        let target = self.top_left + film.x * self.horizontal + film.y * self.vertical;
        let origin = if self.aperture > 0.0 {
            let d = 0.5 * self.aperture * sampling::concentric_disk(lens);
            self.from + d.x * self.u + d.y * self.v
        } else {
            self.from
        };
        Ray::new(origin, (target - origin).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_and_corner_rays() {
        let c = Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, 90.0, 2.0, 0.0, None).unwrap();
        let r = c.ray(Vec2::splat(0.5), Vec2::ZERO);
        assert!((r.dir - -Vec3::Z).length() < 1e-6);
        // vfov 90° and aspect 2: the top-left corner is at (-2, 1, -1).
        let r = c.ray(Vec2::ZERO, Vec2::ZERO);
        assert!((r.dir - Vec3::new(-2.0, 1.0, -1.0).normalize()).length() < 1e-6);
        assert!(Camera::new(Vec3::ZERO, Vec3::ZERO, Vec3::Y, 60.0, 1.0, 0.0, None).is_err());
        assert!(Camera::new(Vec3::ZERO, Vec3::Y, Vec3::Y, 60.0, 1.0, 0.0, None).is_err());
    }
}
