//! Mesh files (OBJ/MTL, PLY; gzipped or not) as shapes of a scene, and a bare mesh as a
//! whole scene: the mesh front end.

use std::path::Path;

use raylab_core::{Rgb, Transform, Vec3};
use raylab_render::{Light, TriangleMesh};

use crate::description::{CameraDescription, SceneDescription, Span};
use crate::error::LoadError;
use crate::files::Found;
use crate::obj::{load_obj, ObjData};

/// The mesh formats a `file` may name, for messages.
pub const MESH_EXTENSIONS: &str = ".obj, .obj.gz, .ply, .ply.gz";

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeshFormat {
    Obj,
    Ply,
}

impl MeshFormat {
    /// The format a file name's extension says (`.gz` looked through), if raylab reads it.
    pub fn of(name: &str) -> Option<Self> {
        let lower = name.to_ascii_lowercase();
        let stem = lower.strip_suffix(".gz").unwrap_or(&lower);
        if stem.ends_with(".obj") {
            Some(Self::Obj)
        } else if stem.ends_with(".ply") {
            Some(Self::Ply)
        } else {
            None
        }
    }

    /// The format, or the error naming what is supported.
    pub fn require(name: &str) -> Result<Self, String> {
        Self::of(name).ok_or_else(|| format!("unsupported mesh format `{name}` (supported: {MESH_EXTENSIONS})"))
    }
}

/// Reads a mesh file: OBJ with the MTL materials it names, or PLY (one mesh, no materials).
pub fn load_mesh_file(found: &Found, to_world: &Transform) -> Result<ObjData, LoadError> {
    let path = found.path();
    let data = match MeshFormat::require(&path.to_string_lossy()).map_err(|e| LoadError::file(&path, e))? {
        MeshFormat::Obj => load_obj(found, to_world)?,
        MeshFormat::Ply => ObjData { meshes: vec![(crate::ply::load_ply(found, to_world)?, None)], materials: Vec::new(), mtl_dir: None, warnings: Vec::new() },
    };
    // A mesh that yields nothing would render as a silent black image: say so instead.
    let triangles: usize = data.meshes.iter().map(|(m, _)| m.indices.len()).sum();
    if triangles == 0 {
        return Err(LoadError::file(&path, "the mesh has no triangles"));
    }
    Ok(data)
}

/// A bare mesh as a scene: a camera framing its bounds from the front and above, a point
/// light beside the camera, a little ambient light, the default material.
pub fn parse_mesh_scene(path: &Path) -> Result<SceneDescription, LoadError> {
    if !path.exists() {
        return Err(LoadError::file(path, "cannot read: no such file"));
    }
    let data = load_mesh_file(&Found::Disk(path.to_path_buf()), &Transform::IDENTITY)?;
    let meshes: Vec<TriangleMesh> = data.meshes.into_iter().map(|(m, _)| m).collect();
    // The camera is placed from the bounds: a mesh without extent has no view to frame, and
    // would otherwise fail with a camera error the user never wrote.
    let first = meshes.iter().find_map(|m| m.indices.first().map(|t| m.positions[t[0] as usize]));
    if let Some(first) = first.filter(|&f| meshes.iter().all(|m| m.indices.iter().flatten().all(|&i| m.positions[i as usize] == f))) {
        return Err(LoadError::file(path, format!("every vertex of its triangles is the same point [{}, {}, {}]: there is nothing to see or frame", first.x, first.y, first.z)));
    }
    let mut desc = framed_description(path, &meshes);
    desc.warnings.extend(data.warnings);
    for mesh in meshes {
        desc.geometry.add_mesh(mesh);
    }
    Ok(desc)
}

/// An empty description whose camera frames the meshes' bounds, lit by a point light beside
/// the camera and a little ambient light; used for bare meshes and scenes without a camera.
pub fn framed_description(path: &Path, meshes: &[TriangleMesh]) -> SceneDescription {
    let mut b = raylab_core::Aabb::EMPTY;
    for m in meshes {
        for &p in &m.positions {
            b = b.grow(p);
        }
    }
    let center = b.centroid();
    // Far from the origin, a camera closer than a few ulps of the centre would coincide
    // with it in single precision.
    let radius = (0.5 * b.extent().length()).max(1e-3).max(center.abs().max_element() * 1e-5);
    let from = center + Vec3::new(0.35, 0.45, 1.0).normalize() * radius * 2.6;
    let span = Span::new(path, None, "camera");
    let camera = CameraDescription { from, at: center, up: Vec3::Y, vfov: 40.0, aperture: 0.0, focus_distance: None, at_span: span.clone(), up_span: span };
    let mut desc = SceneDescription::new(path, camera);
    desc.lights.push(Light::Point { position: from + Vec3::new(-radius, radius, 0.0), intensity: Rgb::splat(3.0 * radius * radius) });
    desc.lights.push(Light::Ambient { intensity: Rgb::splat(0.1) });
    desc
}
