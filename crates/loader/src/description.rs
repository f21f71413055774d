//! The scene description every front end (TOML, OBJ, PLY, pbrt-v4) produces, and that
//! [`crate::build::build_scene`] alone turns into a render [`Scene`](raylab_render::Scene):
//! parse -> description -> build, as pbrt-v4 does. A description holds plain values (the
//! render crate's materials, textures and shapes, all in world space) and the source spans
//! needed to blame a value the builder rejects; it holds no acceleration structure, and its
//! settings are only those the file gave (defaults and command-line overrides are applied
//! by the builder).

use std::path::{Path, PathBuf};

use raylab_core::{Rgb, Vec3};
use raylab_render::light::EnvironmentLight;
use raylab_render::shading::ShadingPerturbation;
use raylab_render::{Background, Geometry, Light, Material, MaterialId, Texture, TextureId};

use crate::error::LoadError;
use raylab_render::Overrides;

/// Where a value came from: the file, its line, and the dotted field (`camera.at`,
/// `Shape "sphere"`), for messages like `scene.toml:3: camera.at: must differ ...`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Span {
    pub file: PathBuf,
    pub line: Option<usize>,
    pub field: String,
}

impl Span {
    pub fn new(file: &Path, line: Option<usize>, field: impl Into<String>) -> Self {
        Self { file: file.to_path_buf(), line, field: field.into() }
    }

    /// An error about the value this span names.
    pub fn err(&self, message: impl Into<String>) -> LoadError {
        LoadError::new(&self.file, self.line, self.field.clone(), message)
    }
}

/// A pinhole or thin-lens camera, as given; its aspect ratio comes from the final image size.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraDescription {
    pub from: Vec3,
    pub at: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub vfov: f32,
    pub aperture: f32,
    pub focus_distance: Option<f32>,
    /// Blamed when `at` coincides with `from`.
    pub at_span: Span,
    /// Blamed when `up` is parallel to the viewing direction.
    pub up_span: Span,
}

/// Everything a scene file says. Material 0 is the default diffuse material, as in
/// [`raylab_render::Scene`], so front ends can leave shapes without one.
#[derive(Debug)]
pub struct SceneDescription {
    /// The file the description was read from (named in the builder's errors).
    pub file: PathBuf,
    pub camera: CameraDescription,
    /// The settings the file gave; the rest default. Command-line overrides win over these.
    pub settings: Overrides,
    /// Where the file set `spp`, blamed when it does not suit the sampler.
    pub spp_span: Option<Span>,
    pub textures: Vec<Texture>,
    pub texture_names: Vec<String>,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    /// Each material's normal or bump map, parallel to `materials`.
    pub material_perturbations: Vec<Option<ShadingPerturbation>>,
    /// Every shape in world space.
    pub geometry: Geometry,
    pub lights: Vec<Light>,
    pub background: Background,
    pub environment: Option<EnvironmentLight>,
    /// Things the front end accepted but wants the user to know (a skipped pbrt directive).
    pub warnings: Vec<String>,
}

impl SceneDescription {
    /// An empty description holding the default material (id 0).
    pub fn new(file: &Path, camera: CameraDescription) -> Self {
        Self {
            file: file.to_path_buf(),
            camera,
            settings: Overrides::default(),
            spp_span: None,
            textures: Vec::new(),
            texture_names: Vec::new(),
            materials: vec![Material::default_diffuse()],
            material_names: vec!["default".into()],
            material_perturbations: vec![None],
            geometry: Geometry::default(),
            lights: Vec::new(),
            background: Background::Color(Rgb::ZERO),
            environment: None,
            warnings: Vec::new(),
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

    /// Triangles of every mesh (what `raylab inspect` reports), for comparing front ends.
    pub fn triangle_count(&self) -> usize {
        self.geometry.triangle_count()
    }
}
