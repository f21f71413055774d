use raylab_core::Vec3;

use crate::shape::SurfaceGeometry;
use crate::texture::Texture;

/// The step in `u` and `v` of the finite differences: pbrt-v4's fallback when a hit has no
/// ray differentials (raylab traces none). Below one texel of a 1024² map, so a bilinear
/// map is differentiated exactly.
const DELTA: f32 = 0.0005;

/// The shading normal of a surface displaced by `scale · h(u, v)` along `ns` (pbrt-v4
/// `BumpMap`): `∂p'/∂u ≈ ∂p/∂u + (d(u + Δ) − d(u)) / Δ · ns`, the same in `v`, and
/// `n' = ∂p'/∂u × ∂p'/∂v` turned to the side of `ns`. `h` is the mean of the texture's
/// channels. Differences from pbrt-v4: the `d · ∂n/∂u` term is dropped (raylab keeps no
/// normal derivatives; it vanishes on flat triangles), and ∂p/∂u, ∂p/∂v are projected onto
/// the shading plane keeping their length, where pbrt's triangles normalise them, so
/// `scale` is a height in world units per unit of texture value.
pub fn bumped_normal(height: &Texture, scale: f32, g: &SurfaceGeometry) -> Vec3 {
    let n = g.ns;
    let d = |du: f32, dv: f32| {
        let c = height.eval(g.uv + raylab_core::Vec2::new(du, dv), g.p + du * g.dpdu + dv * g.dpdv);
        scale * (c.x + c.y + c.z) / 3.0
    };
    let d0 = d(0.0, 0.0);
    let dpdu = g.dpdu - n * n.dot(g.dpdu);
    let dpdv = g.dpdv - n * n.dot(g.dpdv);
    let dpdu = dpdu.try_normalize().map_or(dpdu, |t| t * g.dpdu.length()) + (d(DELTA, 0.0) - d0) / DELTA * n;
    let dpdv = dpdv.try_normalize().map_or(dpdv, |t| t * g.dpdv.length()) + (d(0.0, DELTA) - d0) / DELTA * n;
    match raylab_core::edges::unit_cross(dpdu, dpdv) {
        Some(nb) if nb.dot(n) < 0.0 => -nb,
        Some(nb) => nb,
        None => n,
    }
}
