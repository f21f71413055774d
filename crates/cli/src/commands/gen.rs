//! `raylab gen`: procedural scenes of any size (Haines' SPD, and a furry ball of curves),
//! generated as scene descriptions and written by the TOML writer as a scene file and, for
//! triangle-heavy or hairy scenes, an OBJ mesh or a curve file beside it.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

#[derive(Args, Clone, Debug)]
pub struct GenArgs {
    /// Which scene: balls (sphereflake), rings, tetra (Sierpinski tetrahedron), mount (fractal mountain), hair (furry ball of curves)
    pub kind: String,
    /// Recursion depth or level (balls 1-6, rings 1-64, tetra 1-10, mount 1-11)
    #[arg(long, default_value_t = 3)]
    pub size: u32,
    /// Strands of `hair` (1-1000000)
    #[arg(long, default_value_t = 1000)]
    pub strands: u32,
    /// Cubic curve segments per strand of `hair` (1-64)
    #[arg(long, default_value_t = 4)]
    pub segments: u32,
    /// Scene file to write (.toml); a mesh (`.obj`) or curves (`.curves`) go beside it with the same stem
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(a: &GenArgs) -> Result<()> {
    // The mesh or curves go beside the scene file under the same stem: `-o t.obj` would
    // write the scene and then overwrite it with the mesh.
    if a.output.extension().is_none_or(|e| e != "toml") {
        anyhow::bail!("--output: the scene file must end in .toml (its mesh or curves are written beside it), found {}", a.output.display());
    }
    let stem = a.output.file_stem().and_then(|s| s.to_str()).context("--output: needs a file name")?;
    let size = raylab_procedural::Size { size: a.size, strands: a.strands, segments: a.segments };
    let g = raylab_procedural::generate(&a.kind, size).map_err(anyhow::Error::msg)?;
    let written = raylab_loader::toml_write::write_toml(&g.scene, stem, &g.title).map_err(|e| anyhow::anyhow!("cannot write the generated scene: {e}"))?;
    // Side files first: a scene file never names a file that is not there yet.
    for f in &written.side_files {
        let path = a.output.with_file_name(&f.name);
        raylab_render::film::atomic::write_atomic(&path, &f.contents).with_context(|| format!("{}: cannot write", path.display()))?;
    }
    raylab_render::film::atomic::write_atomic(&a.output, &written.toml).with_context(|| format!("{}: cannot write", a.output.display()))?;
    let geometry = &g.scene.geometry;
    eprintln!("Wrote {} ({} spheres, {} triangles, {} curve segments).", a.output.display(), geometry.spheres.len(), geometry.triangle_count(), g.curve_segments());
    Ok(())
}
