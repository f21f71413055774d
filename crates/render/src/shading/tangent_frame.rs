use raylab_core::Vec3;

/// The orthonormal frame tangent-space normal maps are decoded in: `n` the shading normal,
/// `t` the tangent made orthogonal to it (Gram–Schmidt), `b = sign · (n × t)`.
///
/// MikkTSpace's reference shader interpolates `t` and `n` and uses them unnormalised and
/// not re-orthogonalised per pixel; we orthonormalise, which differs only where the vertex
/// tangents and normals of a triangle disagree strongly. The baker (`raylab_lab::bake`) uses
/// this same frame, so a baked map decodes to the normal it encoded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentFrame {
    pub t: Vec3,
    pub b: Vec3,
    pub n: Vec3,
}

impl TangentFrame {
    /// `n` must be unit length; a tangent parallel to `n` falls back to any perpendicular.
    pub fn new(n: Vec3, tangent: Vec3, sign: f32) -> Self {
        let t = (tangent - n * n.dot(tangent)).try_normalize().unwrap_or_else(|| n.any_orthonormal_vector());
        Self { t, b: sign * n.cross(t), n }
    }

    pub fn to_world(&self, v: Vec3) -> Vec3 {
        v.x * self.t + v.y * self.b + v.z * self.n
    }

    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }
}
