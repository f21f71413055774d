//! Shading-normal perturbation: normal maps (tangent or object space) and bump maps. A
//! perturbation belongs to a material but lives beside the `Material` enum
//! (`Scene::material_perturbations`); `Scene::intersect` applies it once, so every
//! integrator and AOV sees the perturbed `ns`. The geometric normal is left alone: ray
//! offsets and the side tests of the integrators keep using it. Formulas: docs/normal-maps.md.

mod bump;
mod normal_map;
mod tangent_frame;

pub use bump::bumped_normal;
pub use normal_map::{decode_normal, encode_normal, NormalSpace};
pub use tangent_frame::TangentFrame;

use raylab_core::Vec3;

use crate::material::TextureId;
use crate::shape::{Geometry, SurfaceGeometry};
use crate::texture::Texture;

/// How a material bends its shading normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadingPerturbation {
    /// An RGB texture holding `(n + 1) / 2`, decoded in `space`.
    NormalMap { texture: TextureId, space: NormalSpace },
    /// A height texture (the mean of its channels) displacing the surface by
    /// `scale · height` along the shading normal.
    Bump { texture: TextureId, scale: f32 },
}

impl ShadingPerturbation {
    /// Whether meshes with this perturbation need per-vertex tangents.
    pub fn needs_tangents(&self) -> bool {
        matches!(self, ShadingPerturbation::NormalMap { space: NormalSpace::Tangent, .. })
    }

    /// The perturbed unit shading normal at hit `(b1, b2)` of `prim`, kept above the
    /// geometric surface.
    pub fn shading_normal(&self, textures: &[Texture], geometry: &Geometry, prim: u32, b1: f32, b2: f32, geom: &SurfaceGeometry) -> Vec3 {
        let ns = match *self {
            ShadingPerturbation::NormalMap { texture, space } => {
                let n = decode_normal(textures[texture.0 as usize].eval(geom.uv, geom.p));
                match space {
                    NormalSpace::Tangent => {
                        let (t, sign) = geometry.tangent(prim, b1, b2, geom);
                        TangentFrame::new(geom.ns, t, sign).to_world(n)
                    }
                    NormalSpace::Object => geometry.object_normal_to_world(prim, n),
                }
            }
            ShadingPerturbation::Bump { texture, scale } => bumped_normal(&textures[texture.0 as usize], scale, geom),
        };
        keep_above_surface(ns, geom.ng)
    }
}

/// The smallest cosine allowed between a perturbed shading normal and the geometric normal.
pub const MIN_COS_TO_NG: f32 = 0.01;

/// Keeps a unit shading normal in the hemisphere of `ng`, at least [`MIN_COS_TO_NG`] above
/// the tangent plane. pbrt-v4 only flips `ns` into `ng`'s hemisphere (`FaceForward` in
/// `SetShadingGeometry`), which mirrors a normal that a map bends below the surface; we
/// clamp it instead, keeping its tangential direction. Below the surface, a shading normal
/// would reflect light arriving from behind the real surface: a light leak.
pub fn keep_above_surface(ns: Vec3, ng: Vec3) -> Vec3 {
    let cos = ns.dot(ng);
    if cos >= MIN_COS_TO_NG {
        return ns;
    }
    match (ns - cos * ng).try_normalize() {
        Some(t) => t * (1.0 - MIN_COS_TO_NG * MIN_COS_TO_NG).sqrt() + MIN_COS_TO_NG * ng,
        None => ng,
    }
}

#[cfg(test)]
mod tests;
