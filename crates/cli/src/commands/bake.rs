//! `raylab bake`: a tangent-space normal map of a detailed mesh on a simplified one. The low
//! mesh gets an automatic UV atlas and smooth normals and is written beside the map as
//! `<LOW>_uv.obj`; the baking itself is `raylab_lab::bake`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use raylab_core::Transform;
use raylab_lab::bake::{bake_normal_map, with_atlas_uvs};
use raylab_loader::files::{not_found_message, Resolver};
use raylab_loader::image_io::write_linear_png;
use raylab_loader::mesh_scene::load_mesh_file;
use raylab_loader::obj::obj_text;
use raylab_render::TriangleMesh;

#[derive(Args, Clone, Debug)]
pub struct BakeArgs {
    /// The detailed mesh whose normals are baked (.obj or .ply, gzipped or not; looked up in the shared scene folder too)
    #[arg(long)]
    pub high: PathBuf,
    /// The simplified mesh that carries the map (.obj or .ply, gzipped or not); its UV-mapped copy is
    /// written beside the map as <LOW>_uv.obj
    #[arg(long)]
    pub low: PathBuf,
    /// The normal map to write (PNG, linear 8-bit: load it with `srgb = false`)
    #[arg(short, long)]
    pub output: PathBuf,
    /// Width and height of the map in texels
    #[arg(long, default_value_t = 2048)]
    pub size: u32,
    /// How far from the low surface to look for the high one, as a fraction of the low
    /// mesh's bounding-box diagonal
    #[arg(long, default_value_t = 0.01)]
    pub max_distance: f32,
}

pub fn run(a: &BakeArgs) -> Result<()> {
    if !(64..=16384).contains(&a.size) {
        bail!("--size: must be between 64 and 16384, found {}", a.size);
    }
    if !(a.max_distance.is_finite() && a.max_distance > 0.0) {
        bail!("--max-distance: expected a finite number above 0, found {}", a.max_distance);
    }
    let start = Instant::now();
    let high = smooth_mesh(&a.high)?;
    let low = smooth_mesh(&a.low)?;
    let mut low_uv = with_atlas_uvs(&low, a.size).map_err(|e| {
        // Say what would do: the smallest power of two whose atlas fits.
        let fits = (7..=14).map(|k| 1u32 << k).find(|&s| s > a.size && with_atlas_uvs(&low, s).is_ok());
        match fits {
            Some(s) => anyhow::anyhow!("--size: {e} (use --size {s} or more)"),
            None => anyhow::anyhow!("--size: {e} (even 16384 is too small: simplify the low mesh)"),
        }
    })?;
    low_uv.compute_tangents();
    let max_distance = a.max_distance * low.bounds().extent().length();
    eprintln!("Loaded {} and {} triangles in {:.2} s; baking {}² texels...", high.len(), low.len(), start.elapsed().as_secs_f64(), a.size);
    let bake_start = Instant::now();
    let map = bake_normal_map(&low_uv, &high, a.size, max_distance);
    let bake_seconds = bake_start.elapsed().as_secs_f64();
    write_linear_png(&a.output, a.size, a.size, &map.texels)?;
    let obj_path = a.output.with_file_name(format!("{}_uv.obj", mesh_stem(&a.low)));
    raylab_render::film::atomic::write_atomic(&obj_path, obj_text(&low_uv)).with_context(|| format!("{}: cannot write", obj_path.display()))?;
    eprintln!(
        "Wrote {} and {}: {} texels covered, {:.2}% found the high mesh within {max_distance:.3e}; baked in {bake_seconds:.2} s.",
        a.output.display(),
        obj_path.display(),
        map.covered,
        100.0 * map.hits as f64 / map.covered.max(1) as f64
    );
    Ok(())
}

/// Every mesh of a mesh file as one, with angle-weighted normals unless it has its own (the
/// `smooth = true` of scene files, so the map matches what the renderer shades).
fn smooth_mesh(path: &Path) -> Result<TriangleMesh> {
    // Found as scene files find meshes: the path itself, then `shared/scenes` of the current
    // folder's ancestors (where the README's dragon lives); the error lists every path tried.
    let name = path.to_string_lossy();
    let found = Resolver::Disk { base: PathBuf::new() }.find(&name).map_err(|tried| anyhow::anyhow!("{}", not_found_message(&name, &tried)))?;
    let obj = load_mesh_file(&found, &Transform::IDENTITY)?;
    let mut all = TriangleMesh { name: mesh_stem(path), ..Default::default() };
    let mut with_normals = true;
    for (mesh, _) in obj.meshes {
        let base = all.positions.len() as u32;
        with_normals &= !mesh.normals.is_empty();
        all.positions.extend(&mesh.positions);
        all.normals.extend(&mesh.normals);
        all.indices.extend(mesh.indices.iter().map(|t| t.map(|i| i + base)));
    }
    if all.is_empty() {
        bail!("{}: the mesh has no triangles", path.display());
    }
    if !with_normals {
        all.compute_smooth_normals(180.0);
    }
    Ok(all)
}

/// `dragon.obj.gz` → `dragon`.
fn mesh_stem(path: &Path) -> String {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    name.trim_end_matches(".gz").trim_end_matches(".obj").trim_end_matches(".ply").to_string()
}
