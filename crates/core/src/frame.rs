use glam::Vec3;

/// An orthonormal basis `(x, y, z)` with `z` the given normal.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub x: Vec3,
    pub y: Vec3,
    pub z: Vec3,
}

impl Frame {
    /// Branchless basis from a unit vector (Duff et al. 2017, "Building an Orthonormal
    /// Basis, Revisited"): continuous everywhere except at one sign flip, no normalisation.
    pub fn from_z(z: Vec3) -> Self {
        let sign = 1.0f32.copysign(z.z);
        let a = -1.0 / (sign + z.z);
        let b = z.x * z.y * a;
        let x = Vec3::new(1.0 + sign * z.x * z.x * a, sign * b, -sign * z.x);
        let y = Vec3::new(b, sign + z.y * z.y * a, -z.y);
        Self { x, y, z }
    }

    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    pub fn to_world(&self, v: Vec3) -> Vec3 {
        v.x * self.x + v.y * self.y + v.z * self.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal() {
        for z in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.3, -0.5, 0.8).normalize(), Vec3::new(0.0, 0.0, -1.0)] {
            let f = Frame::from_z(z);
            assert!((f.x.length() - 1.0).abs() < 1e-5);
            assert!((f.y.length() - 1.0).abs() < 1e-5);
            assert!(f.x.dot(f.y).abs() < 1e-5 && f.x.dot(f.z).abs() < 1e-5 && f.y.dot(f.z).abs() < 1e-5);
            let v = Vec3::new(0.1, 0.2, 0.3);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }
}
