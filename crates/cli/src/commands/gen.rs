//! `raylab gen`: procedural scenes of any size (Haines' SPD), written as a scene file and,
//! for triangle-heavy scenes, an OBJ mesh beside it.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

#[derive(Args, Clone, Debug)]
pub struct GenArgs {
    /// Which scene: balls (sphereflake), rings, tetra (Sierpinski tetrahedron), mount (fractal mountain)
    pub kind: String,
    /// Recursion depth or level (balls 1-6, rings 1-64, tetra 1-10, mount 1-11)
    #[arg(long, default_value_t = 3)]
    pub size: u32,
    /// Scene file to write; a mesh goes beside it with the same stem and `.obj`
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(a: &GenArgs) -> Result<()> {
    let stem = a.output.file_stem().and_then(|s| s.to_str()).context("--output: needs a file name")?;
    let mesh_name = format!("{stem}.obj");
    let g = raylab_procedural::generate(&a.kind, a.size, &mesh_name).map_err(anyhow::Error::msg)?;
    std::fs::write(&a.output, &g.toml).with_context(|| format!("{}: cannot write", a.output.display()))?;
    if let Some(obj) = &g.obj {
        let mesh_path = a.output.with_file_name(&mesh_name);
        std::fs::write(&mesh_path, obj).with_context(|| format!("{}: cannot write", mesh_path.display()))?;
    }
    eprintln!("Wrote {} ({} spheres, {} triangles).", a.output.display(), g.spheres, g.triangles);
    Ok(())
}
