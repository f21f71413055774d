//! Materials: what a surface does with light. Whitted shading reads their parameters
//! directly (`integrator/whitted.rs`).

use raylab_core::{Rgb, Vec2, Vec3};

use crate::bsdf::{Bsdf, Distribution, Fresnel, Geometry as MicrofacetGeometry};
use crate::texture::Texture;

/// Index of a material in [`crate::Scene::materials`]; 0 is the default grey diffuse.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct MaterialId(pub u32);

/// Index of a texture in [`crate::Scene::textures`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureId(pub u32);

/// A colour parameter: a constant or a texture lookup.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TexColor {
    Constant(Rgb),
    Texture(TextureId),
}

impl TexColor {
    #[inline]
    pub fn eval(&self, textures: &[Texture], uv: Vec2, p: Vec3) -> Rgb {
        match *self {
            TexColor::Constant(c) => c,
            TexColor::Texture(t) => textures[t.0 as usize].eval(uv, p),
        }
    }
}

impl From<Rgb> for TexColor {
    fn from(c: Rgb) -> Self {
        TexColor::Constant(c)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// Lambertian reflection, BRDF `albedo / π`.
    Diffuse { albedo: TexColor },
    /// The classic Phong model (Phong 1975) as the seeds use it:
    /// `ka·I_ambient + Σ (kd·cos θ + ks·max(0, r·v)^exponent) · I / d²`.
    Phong { ka: TexColor, kd: TexColor, ks: TexColor, exponent: f32 },
    /// Ideal specular reflection scaled by `reflectance`.
    Mirror { reflectance: TexColor },
    /// Smooth dielectric (glass, water): Snell refraction weighted by the exact unpolarised
    /// Fresnel term; total internal reflection. `ior` is inside over outside (outside = 1).
    Dielectric { ior: f32 },
    /// Cook–Torrance microfacet reflection over a Lambertian base (see `crate::bsdf`):
    /// `f = diffuse/π + specular·D·G·F / (4 cos θi cos θo)`, `roughness` = α.
    CookTorrance { diffuse: TexColor, specular: TexColor, roughness: f32, distribution: Distribution, geometry: MicrofacetGeometry, f0: TexColor },
    /// Rough metal (pbrt-v4's `conductor`): the same microfacet reflection with the exact
    /// Fresnel reflectance of complex index `eta + i·k` per channel and no diffuse base.
    Conductor { eta: Rgb, k: Rgb, roughness: f32, distribution: Distribution, geometry: MicrofacetGeometry },
    /// Kajiya–Kay hair along the surface's tangent `dpdu` (curves, tubes):
    /// `f = (color·kd·sin(T, ωi) + ks·cos^exponent θ') / π` (see `crate::bsdf`).
    Hair { color: TexColor, kd: f32, ks: f32, exponent: f32 },
    /// glTF 2.0's metallic-roughness material (also Blender's Principled BSDF without its
    /// extra lobes): base colour `b = base_color`, metalness `m = metallic · B` and perceptual
    /// roughness `r = roughness · G`, where B and G are the blue and green channels of the
    /// linear `metallic_roughness` texture (1 without one). It is the Cook–Torrance BRDF with
    /// diffuse `b·(1 − m)`, Schlick `f0 = lerp(0.04, b, m)` and GGX–Smith `α = r²`, per
    /// shading point, so that textured metalness and roughness vary across the surface.
    MetallicRoughness { base_color: TexColor, metallic: f32, roughness: f32, metallic_roughness: Option<TextureId> },
}

/// Complex refractive indices `(eta, k)` of common metals at the R, G and B primaries
/// (the usual RGB fits of measured spectra), for `conductor` materials.
pub const METALS: &[(&str, [f32; 3], [f32; 3])] = &[
    ("gold", [0.143, 0.374, 1.442], [3.983, 2.385, 1.603]),
    ("silver", [0.155, 0.117, 0.138], [4.828, 3.122, 2.147]),
    ("copper", [0.200, 0.924, 1.102], [3.912, 2.452, 2.142]),
    ("aluminium", [1.657, 0.880, 0.521], [9.224, 6.270, 4.837]),
];

impl Material {
    /// The physically based BSDF at a surface point (textures looked up at `uv`, `p`). The
    /// Phong material becomes the energy-normalised Phong lobe; `ka` has no place in it.
    pub fn bsdf(&self, textures: &[Texture], uv: Vec2, p: Vec3) -> Bsdf {
        let c = |t: &TexColor| t.eval(textures, uv, p);
        match self {
            Material::Diffuse { albedo } => Bsdf::Lambert { albedo: c(albedo) },
            Material::Phong { kd, ks, exponent, .. } => Bsdf::Phong { kd: c(kd), ks: c(ks), exponent: *exponent },
            Material::Mirror { reflectance } => Bsdf::Mirror { reflectance: c(reflectance) },
            Material::Dielectric { ior } => Bsdf::Dielectric { ior: *ior },
            Material::CookTorrance { diffuse, specular, roughness, distribution, geometry, f0 } => {
                Bsdf::CookTorrance { diffuse: c(diffuse), specular: c(specular), alpha: *roughness, distribution: *distribution, geometry: *geometry, fresnel: Fresnel::Schlick(c(f0)) }
            }
            Material::Conductor { eta, k, roughness, distribution, geometry } => {
                Bsdf::CookTorrance { diffuse: Rgb::ZERO, specular: Rgb::ONE, alpha: *roughness, distribution: *distribution, geometry: *geometry, fresnel: Fresnel::Conductor { eta: *eta, k: *k } }
            }
            Material::Hair { color, kd, ks, exponent } => Bsdf::KajiyaKay { color: c(color), kd: *kd, ks: *ks, exponent: *exponent },
            Material::MetallicRoughness { base_color, metallic, roughness, metallic_roughness } => {
                let base = c(base_color);
                let (m, r) = metallic_roughness_at(*metallic, *roughness, metallic_roughness.map(|t| c(&TexColor::Texture(t))));
                Bsdf::CookTorrance {
                    diffuse: base * (1.0 - m),
                    specular: Rgb::ONE,
                    alpha: (r * r).max(MIN_ALPHA),
                    distribution: Distribution::Ggx,
                    geometry: MicrofacetGeometry::Smith,
                    fresnel: Fresnel::Schlick(Rgb::splat(0.04).lerp(base, m)),
                }
            }
        }
    }

    /// The diffuse colour (the `albedo` AOV).
    pub fn albedo(&self, textures: &[Texture], uv: Vec2, p: Vec3) -> Rgb {
        let c = |t: &TexColor| t.eval(textures, uv, p);
        match self {
            Material::Diffuse { albedo } => c(albedo),
            Material::Phong { kd, .. } => c(kd),
            Material::Mirror { reflectance } => c(reflectance),
            Material::Dielectric { .. } => Rgb::ONE,
            Material::CookTorrance { diffuse, specular, .. } => c(diffuse) + c(specular),
            Material::Conductor { eta, k, .. } => Fresnel::Conductor { eta: *eta, k: *k }.eval(1.0),
            Material::Hair { color, .. } => c(color),
            Material::MetallicRoughness { base_color, .. } => c(base_color),
        }
    }

    pub fn default_diffuse() -> Self {
        Material::Diffuse { albedo: TexColor::Constant(Rgb::splat(0.5)) }
    }

    pub fn type_name(&self) -> &'static str {
        match self {
            Material::Diffuse { .. } => "diffuse",
            Material::Phong { .. } => "phong",
            Material::Mirror { .. } => "mirror",
            Material::Dielectric { .. } => "dielectric",
            Material::CookTorrance { .. } => "cooktorrance",
            Material::Conductor { .. } => "conductor",
            Material::Hair { .. } => "hair",
            Material::MetallicRoughness { .. } => "metallic-roughness",
        }
    }
}

/// The smallest GGX α a metallic-roughness material gets: roughness 0 would be a mirror,
/// which the microfacet lobe cannot sample (as glTF viewers clamp it).
pub const MIN_ALPHA: f32 = 1e-3;

/// Metalness and perceptual roughness at a point: the factors times the texture's blue
/// (metalness) and green (roughness) channels, as glTF packs them, clamped to [0, 1].
pub fn metallic_roughness_at(metallic: f32, roughness: f32, texel: Option<Rgb>) -> (f32, f32) {
    let t = texel.unwrap_or(Rgb::ONE);
    ((metallic * t.z).clamp(0.0, 1.0), (roughness * t.y).clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{Checker, CheckerSpace};

    fn close(a: Rgb, b: Rgb) -> bool {
        (a - b).abs().max_element() < 1e-6
    }

    /// Texture 0 a constant, texture 1 a uv checker (white at the origin's cell, black in the next).
    fn textures() -> Vec<Texture> {
        let checker = Checker { even: Rgb::ONE, odd: Rgb::ZERO, scale: 2.0, space: CheckerSpace::Uv };
        vec![Texture::Constant(Rgb::new(0.1, 0.2, 0.3)), Texture::Checker(checker)]
    }

    #[test]
    fn tex_colors_are_constants_or_lookups() {
        let t = textures();
        let c = Rgb::new(0.7, 0.6, 0.5);
        assert_eq!(TexColor::from(c), TexColor::Constant(c));
        assert_eq!(TexColor::Constant(c).eval(&t, Vec2::ZERO, Vec3::ZERO), c);
        assert_eq!(TexColor::Texture(TextureId(0)).eval(&t, Vec2::ZERO, Vec3::ZERO), Rgb::new(0.1, 0.2, 0.3));
        assert_eq!(TexColor::Texture(TextureId(1)).eval(&t, Vec2::splat(0.2), Vec3::ZERO), Rgb::ONE);
        assert_eq!(TexColor::Texture(TextureId(1)).eval(&t, Vec2::new(0.7, 0.2), Vec3::ZERO), Rgb::ZERO);
    }

    #[test]
    fn metallic_roughness_scales_by_blue_and_green_and_clamps() {
        // Blue 0.25 scales metalness 0.5 to 0.125, green 0.5 roughness 0.6 to 0.3; red is ignored.
        assert_eq!(metallic_roughness_at(0.5, 0.6, Some(Rgb::new(0.9, 0.5, 0.25))), (0.125, 0.3));
        assert_eq!(metallic_roughness_at(0.5, 0.6, None), (0.5, 0.6));
        assert_eq!(metallic_roughness_at(2.0, 3.0, Some(Rgb::new(0.0, 0.5, 0.75))), (1.0, 1.0));
        assert_eq!(metallic_roughness_at(-0.5, -1.0, None), (0.0, 0.0));
    }

    #[test]
    fn metallic_roughness_bsdf_by_hand() {
        let t = textures();
        // Base (0.8, 0.4, 0.2); metalness 0.5 × blue 0.5 = 0.25; roughness 0.6 × green 0.5 = 0.3.
        let t = [t, vec![Texture::Constant(Rgb::new(0.0, 0.5, 0.5))]].concat();
        let m = Material::MetallicRoughness { base_color: Rgb::new(0.8, 0.4, 0.2).into(), metallic: 0.5, roughness: 0.6, metallic_roughness: Some(TextureId(2)) };
        let Bsdf::CookTorrance { diffuse, specular, alpha, distribution, geometry, fresnel: Fresnel::Schlick(f0) } = m.bsdf(&t, Vec2::ZERO, Vec3::ZERO) else { panic!() };
        // Diffuse b·(1 − m) = 0.75 b; α = r² = 0.09; f0 = 0.04 + 0.25·(b − 0.04).
        assert!(close(diffuse, Rgb::new(0.6, 0.3, 0.15)), "{diffuse}");
        assert_eq!(specular, Rgb::ONE);
        assert!((alpha - 0.09).abs() < 1e-7, "{alpha}");
        assert_eq!((distribution, geometry), (Distribution::Ggx, MicrofacetGeometry::Smith));
        assert!(close(f0, Rgb::new(0.23, 0.13, 0.08)), "{f0}");
        assert_eq!(m.albedo(&t, Vec2::ZERO, Vec3::ZERO), Rgb::new(0.8, 0.4, 0.2));
        // Roughness 0 is held at α = 10⁻³; full metal has no diffuse and f0 = b.
        let m = Material::MetallicRoughness { base_color: Rgb::new(0.8, 0.4, 0.2).into(), metallic: 1.0, roughness: 0.0, metallic_roughness: None };
        let Bsdf::CookTorrance { diffuse, alpha, fresnel: Fresnel::Schlick(f0), .. } = m.bsdf(&t, Vec2::ZERO, Vec3::ZERO) else { panic!() };
        assert_eq!((diffuse, alpha), (Rgb::ZERO, MIN_ALPHA));
        assert!(close(f0, Rgb::new(0.8, 0.4, 0.2)), "{f0}");
    }

    #[test]
    fn every_material_maps_to_its_bsdf_and_albedo() {
        let t = textures();
        let (uv, p) = (Vec2::new(0.7, 0.2), Vec3::ZERO); // the checker's black cell
        let tex = TexColor::Texture(TextureId(1));
        let (a, b) = (Rgb::new(0.1, 0.2, 0.3), Rgb::new(0.4, 0.5, 0.6));
        let at = |m: &Material| (m.bsdf(&t, uv, p), m.albedo(&t, uv, p), m.type_name());
        assert_eq!(at(&Material::Diffuse { albedo: a.into() }), (Bsdf::Lambert { albedo: a }, a, "diffuse"));
        assert_eq!(at(&Material::Diffuse { albedo: tex }), (Bsdf::Lambert { albedo: Rgb::ZERO }, Rgb::ZERO, "diffuse"));
        assert_eq!(at(&Material::Phong { ka: Rgb::ONE.into(), kd: a.into(), ks: b.into(), exponent: 20.0 }), (Bsdf::Phong { kd: a, ks: b, exponent: 20.0 }, a, "phong"));
        assert_eq!(at(&Material::Mirror { reflectance: b.into() }), (Bsdf::Mirror { reflectance: b }, b, "mirror"));
        assert_eq!(at(&Material::Dielectric { ior: 1.5 }), (Bsdf::Dielectric { ior: 1.5 }, Rgb::ONE, "dielectric"));
        let ct = Material::CookTorrance { diffuse: a.into(), specular: b.into(), roughness: 0.2, distribution: Distribution::Beckmann, geometry: MicrofacetGeometry::Smith, f0: Rgb::splat(0.04).into() };
        let want = Bsdf::CookTorrance { diffuse: a, specular: b, alpha: 0.2, distribution: Distribution::Beckmann, geometry: MicrofacetGeometry::Smith, fresnel: Fresnel::Schlick(Rgb::splat(0.04)) };
        // The albedo AOV of Cook–Torrance is diffuse + specular: (0.5, 0.7, 0.9).
        let (bsdf, albedo, name) = at(&ct);
        assert_eq!((bsdf, name), (want, "cooktorrance"));
        assert!(close(albedo, Rgb::new(0.5, 0.7, 0.9)), "{albedo}");
        // Gold: the albedo is the reflectance at normal incidence ((η − 1)² + k²) / ((η + 1)² + k²).
        let (eta, k) = (Rgb::new(0.143, 0.374, 1.442), Rgb::new(3.983, 2.385, 1.603));
        let (bsdf, albedo, name) = at(&Material::Conductor { eta, k, roughness: 0.3, distribution: Distribution::Ggx, geometry: MicrofacetGeometry::Smith });
        assert_eq!((bsdf, name), (Bsdf::CookTorrance { diffuse: Rgb::ZERO, specular: Rgb::ONE, alpha: 0.3, distribution: Distribution::Ggx, geometry: MicrofacetGeometry::Smith, fresnel: Fresnel::Conductor { eta, k } }, "conductor"));
        assert!((albedo - Rgb::new(0.966688, 0.802537, 0.324034)).abs().max_element() < 1e-5, "{albedo}");
        assert_eq!(at(&Material::Hair { color: a.into(), kd: 0.6, ks: 0.4, exponent: 30.0 }), (Bsdf::KajiyaKay { color: a, kd: 0.6, ks: 0.4, exponent: 30.0 }, a, "hair"));
        let mr = Material::MetallicRoughness { base_color: a.into(), metallic: 0.0, roughness: 1.0, metallic_roughness: None };
        assert_eq!((at(&mr).1, at(&mr).2), (a, "metallic-roughness"));
        assert_eq!(Material::default_diffuse(), Material::Diffuse { albedo: TexColor::Constant(Rgb::splat(0.5)) });
    }
}
