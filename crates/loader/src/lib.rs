//! The only crate that reads (and writes) files: scene files (TOML), meshes (OBJ/MTL,
//! gzipped or not), Bézier patches, textures and output images. Every error names the
//! file, the line and the field.

mod curves;
pub mod error;
pub mod files;
pub mod image_io;
pub mod obj;
pub mod patches;
pub mod scene;
mod toml_read;

use std::path::Path;

pub use error::LoadError;
pub use scene::{load_mesh_scene, load_scene, load_scene_str, Overrides};

/// Loads a scene file (`.toml`) or a bare mesh (`.obj`, `.obj.gz`).
pub fn load_scene_or_mesh(path: &Path, overrides: &Overrides) -> Result<raylab_render::Scene, LoadError> {
    let name = path.to_string_lossy();
    if name.ends_with(".obj") || name.ends_with(".obj.gz") {
        load_mesh_scene(path, overrides)
    } else {
        load_scene(path, overrides)
    }
}

/// The text of the embedded default scene.
pub const DEFAULT_SCENE: &str = include_str!("default_scene.toml");

/// The default scene, built from text and meshes compiled into the binary.
pub fn default_scene(overrides: &Overrides) -> Result<raylab_render::Scene, LoadError> {
    load_scene_str(DEFAULT_SCENE, Path::new("<default scene>"), &files::Resolver::Embedded, overrides)
}
