//! The only crate that reads (and writes) files. Every format is a front end that produces
//! a [`SceneDescription`]; one builder ([`build::build_scene`]) turns a description into a
//! render scene: parse -> description -> build, as pbrt-v4 does. Front ends: TOML
//! ([`scene`]), pbrt-v4 ([`pbrt`]), glTF 2.0 ([`gltf`]), bare meshes (OBJ/MTL, PLY: [`mesh_scene`]). Every error names the file, the
//! line and the field.

pub mod build;
mod curves;
pub mod description;
pub mod error;
pub mod files;
pub mod gltf;
pub mod image_io;
pub mod mesh_scene;
pub mod obj;
mod obj_read;
pub mod octahedral;
pub mod patches;
pub mod pbrt;
pub mod ply;
pub mod scene;
mod toml_read;
pub mod toml_write;

use std::path::Path;

pub use build::{black_render_warnings, build_scene};
pub use description::{SceneDescription, Span};
pub use error::LoadError;
pub use scene::{load_scene, load_scene_str, parse_scene_str, Overrides};

/// The scene formats `raylab render FILE` opens, for messages.
pub const SCENE_EXTENSIONS: &str = ".toml, .pbrt, .gltf, .glb, .obj, .obj.gz, .ply, .ply.gz";

/// Reads any scene file or bare mesh into a description, chosen by extension; an unknown
/// extension is an error listing the supported ones. `lenient`: skip, with a warning, what
/// a front end does not support.
pub fn parse_any(path: &Path, lenient: bool) -> Result<SceneDescription, LoadError> {
    let name = path.to_string_lossy();
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".gltf") || lower.ends_with(".glb") {
        return gltf::parse_gltf(path);
    }
    if name.to_ascii_lowercase().ends_with(".pbrt") {
        return pbrt::parse_pbrt(path, lenient);
    }
    if mesh_scene::MeshFormat::of(&name).is_some() {
        return mesh_scene::parse_mesh_scene(path);
    }
    if name.to_ascii_lowercase().ends_with(".toml") {
        let src = files::read_text(path)?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        return parse_scene_str(&src, path, &files::Resolver::Disk { base });
    }
    Err(LoadError::file(path, format!("unsupported file type (supported: {SCENE_EXTENSIONS})")))
}

/// Loads a scene file (`.toml`) or a bare mesh (`.obj`, `.ply`, gzipped or not).
pub fn load_scene_or_mesh(path: &Path, overrides: &Overrides) -> Result<raylab_render::Scene, LoadError> {
    let desc = parse_any(path, overrides.lenient)?;
    for w in &desc.warnings {
        eprintln!("warning: {w}");
    }
    build_scene(desc, overrides)
}

/// A bare mesh (OBJ, PLY) as a scene framed by the camera.
pub fn load_mesh_scene(path: &Path, overrides: &Overrides) -> Result<raylab_render::Scene, LoadError> {
    build_scene(mesh_scene::parse_mesh_scene(path)?, overrides)
}

/// The text of the embedded default scene.
pub const DEFAULT_SCENE: &str = include_str!("default_scene.toml");

/// The default scene, built from text and meshes compiled into the binary.
pub fn default_scene(overrides: &Overrides) -> Result<raylab_render::Scene, LoadError> {
    load_scene_str(DEFAULT_SCENE, Path::new("<default scene>"), &files::Resolver::Embedded, overrides)
}
