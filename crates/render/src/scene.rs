use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters, Hit, Primitives};
use raylab_core::{offset_ray_origin, Ray, Rgb, Vec3};

use crate::camera::Camera;
use crate::light::{AreaLights, EnvironmentLight, Light};
use crate::material::{Material, MaterialId, TextureId};
use crate::settings::RenderSettings;
use crate::shading::ShadingPerturbation;
use crate::shape::{Geometry, SurfaceGeometry};
use crate::texture::{equirect_uv, Texture};

/// What is seen where no geometry is hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Background {
    Color(Rgb),
    /// An equirectangular texture looked up by ray direction.
    Texture(TextureId),
}

/// A hit with everything shading needs.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    pub t: f32,
    pub prim: u32,
    pub geom: SurfaceGeometry,
    pub material: MaterialId,
}

impl SurfaceHit {
    /// A ray leaving the surface towards `dir`, its origin moved off the surface robustly.
    pub fn spawn(&self, dir: Vec3) -> Ray {
        Ray::new(offset_ray_origin(self.geom.p, self.geom.p_error, self.geom.ng, dir), dir)
    }

    /// A shadow ray towards a point at distance `dist` along unit `wi` (∞ for directional
    /// lights). Stops just short of the target so it cannot hit what the target lies on.
    pub fn spawn_to(&self, wi: Vec3, dist: f32) -> Ray {
        let o = offset_ray_origin(self.geom.p, self.geom.p_error, self.geom.ng, wi);
        Ray::segment(o, wi, 0.0, dist * (1.0 - 1e-4))
    }
}

/// A scene ready to render: geometry and its acceleration structure, materials, textures,
/// lights, camera and settings. Everything in world space.
#[derive(Debug)]
pub struct Scene {
    pub camera: Camera,
    pub settings: RenderSettings,
    pub geometry: Geometry,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    /// Each material's normal or bump map, if any, parallel to `materials` (kept out of the
    /// `Material` enum so that every material kind can have one).
    pub material_perturbations: Vec<Option<ShadingPerturbation>>,
    pub textures: Vec<Texture>,
    pub texture_names: Vec<String>,
    pub lights: Vec<Light>,
    pub background: Background,
    /// An importance-sampled environment map; when present it is the background.
    pub environment: Option<EnvironmentLight>,
    /// The emitting primitives, rebuilt with the acceleration structure.
    pub area_lights: AreaLights,
    accel: AnyAccel,
}

impl Scene {
    /// An empty scene holding the default material (id 0).
    pub fn new(camera: Camera, settings: RenderSettings) -> Self {
        let geometry = Geometry::default();
        let accel = AnyAccel::build(AccelKind::None, &geometry, &BuildOptions::default());
        Self {
            camera,
            settings,
            geometry,
            materials: vec![Material::default_diffuse()],
            material_names: vec!["default".into()],
            material_perturbations: vec![None],
            textures: Vec::new(),
            texture_names: Vec::new(),
            lights: Vec::new(),
            background: Background::Color(Rgb::ZERO),
            environment: None,
            area_lights: AreaLights::default(),
            accel,
        }
    }

    /// (Re)builds the acceleration structure named in the settings, and the tangents of
    /// meshes whose material has a tangent-space normal map; call after the geometry changes.
    pub fn build_accel(&mut self, opts: &BuildOptions) {
        for mesh in &mut self.geometry.meshes {
            let needs = self.material_perturbations[mesh.material.0 as usize].is_some_and(|p| p.needs_tangents());
            if needs && mesh.tangents.is_empty() && !mesh.uvs.is_empty() {
                mesh.compute_tangents();
            }
        }
        self.accel = AnyAccel::build(self.settings.accel, &self.geometry, opts);
        self.area_lights = AreaLights::new(&self.geometry, self.settings.light_cells);
    }

    pub fn accel(&self) -> &AnyAccel {
        &self.accel
    }

    /// Closest hit along the ray.
    pub fn intersect(&self, ray: &Ray, counters: &mut Counters) -> Option<SurfaceHit> {
        debug_assert_eq!(self.accel.stats().primitives, self.geometry.len(), "build_accel() after adding geometry");
        let h = self.accel.intersect(&self.geometry, ray, counters)?;
        Some(self.surface_hit(ray, &h))
    }

    /// Closest hits of a packet of camera rays (at most [`raylab_accel::PACKET`]): the same
    /// answers as [`Scene::intersect`] ray by ray, traversed together by wide BVHs.
    pub fn intersect_packet(&self, rays: &[Ray], out: &mut [Option<SurfaceHit>], counters: &mut Counters) {
        debug_assert_eq!(self.accel.stats().primitives, self.geometry.len(), "build_accel() after adding geometry");
        let mut hits = [None; raylab_accel::PACKET];
        let hits = &mut hits[..rays.len()];
        self.accel.intersect_packet_counted(&self.geometry, rays, hits, counters);
        for ((o, h), ray) in out.iter_mut().zip(hits.iter()).zip(rays) {
            *o = h.as_ref().map(|h| self.surface_hit(ray, h));
        }
    }

    /// The surface record of `h`, a hit of `ray`: geometry, shading normal, material.
    fn surface_hit(&self, ray: &Ray, h: &Hit) -> SurfaceHit {
        let material = self.geometry.material(h.prim);
        let mut geom = self.geometry.surface(ray, h.prim, h.t, h.u, h.v);
        if let Some(p) = &self.material_perturbations[material.0 as usize] {
            geom.ns = p.shading_normal(&self.textures, &self.geometry, h.prim, h.u, h.v, &geom);
        }
        SurfaceHit { t: h.t, prim: h.prim, geom, material }
    }

    pub fn occluded(&self, ray: &Ray, counters: &mut Counters) -> bool {
        self.accel.occluded(&self.geometry, ray, counters)
    }

    /// Radiance the surface at `hit` emits towards `w` (zero for non-emitters), its emission
    /// texture applied.
    pub fn emitted(&self, hit: &SurfaceHit, w: Vec3) -> Rgb {
        let le = self.geometry.emitted(hit.prim, &hit.geom, w);
        match self.geometry.emission_texture(hit.prim) {
            Some(t) if le != Rgb::ZERO => le * self.textures[t.0 as usize].eval(hit.geom.uv, hit.geom.p),
            _ => le,
        }
    }

    pub fn background(&self, dir: Vec3) -> Rgb {
        if let Some(env) = &self.environment {
            return env.radiance(dir);
        }
        match self.background {
            Background::Color(c) => c,
            Background::Texture(t) => self.textures[t.0 as usize].eval(equirect_uv(dir.normalize()), dir),
        }
    }

    pub fn add_material(&mut self, name: impl Into<String>, m: Material) -> MaterialId {
        self.materials.push(m);
        self.material_names.push(name.into());
        self.material_perturbations.push(None);
        MaterialId(self.materials.len() as u32 - 1)
    }

    pub fn add_texture(&mut self, name: impl Into<String>, t: Texture) -> TextureId {
        self.textures.push(t);
        self.texture_names.push(name.into());
        TextureId(self.textures.len() as u32 - 1)
    }
}
