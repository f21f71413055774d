//! Options shared by the commands that load a scene.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use raylab_accel::AccelKind;
use raylab_loader::Overrides;
use raylab_render::filter::PixelFilter;
use raylab_render::light::LightSampling;
use raylab_render::integrator::MisHeuristic;
use raylab_render::{IntegratorKind, SamplerKind, Scene};

#[derive(Args, Clone, Debug, Default)]
pub struct SceneArgs {
    /// Scene file (TOML) or bare mesh (OBJ, .obj.gz); the embedded default scene when omitted
    pub scene: Option<PathBuf>,
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// Samples per pixel (a square number for the jittered sampler)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1048576))]
    pub spp: Option<u32>,
    /// Area-light sampling of direct and path: uniform, solid-angle, cells, bsdf or mis
    #[arg(long)]
    pub light_sampling: Option<String>,
}

/// The overrides of a scene's settings other than samples per pixel and light sampling,
/// which `raylab converge` varies itself.
#[derive(Args, Clone, Debug, Default)]
pub struct SettingsArgs {
    /// Image width in pixels (overrides the scene's)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene's)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub height: Option<u32>,
    /// Pixel sampler: random, jittered (stratified) or sobol (scrambled low-discrepancy)
    #[arg(long)]
    pub sampler: Option<String>,
    /// Maximum number of path segments from the camera
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub max_depth: Option<u32>,
    /// Integrator: whitted, direct, path, normals, albedo, depth, heatmap, heatmap-tests
    #[arg(long)]
    pub integrator: Option<String>,
    /// Acceleration structure (none, bvh, ...; see `raylab inspect --help`)
    #[arg(long)]
    pub accel: Option<String>,
    /// Pixel filter: box, tent or gaussian
    #[arg(long)]
    pub filter: Option<String>,
    /// MIS weights of light and BSDF samples: power (default) or balance
    #[arg(long)]
    pub mis_heuristic: Option<String>,
    /// Cells per side of the `cells` light-sampling grid (1 to 16; default 8)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub light_cells: Option<u32>,
    /// Seed of the per-pixel random streams
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads (default: all cores)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
}

impl SettingsArgs {
    /// The overrides, with no spp or light sampling.
    pub fn overrides(&self) -> Result<Overrides> {
        let parse_accel = |s: &String| s.parse::<AccelKind>().map_err(|e| anyhow::anyhow!("--accel: {e}"));
        Ok(Overrides {
            width: self.width,
            height: self.height,
            max_depth: self.max_depth,
            sampler: self.sampler.as_ref().map(|s| s.parse::<SamplerKind>().map_err(|e| anyhow::anyhow!("--sampler: {e}"))).transpose()?,
            integrator: self.integrator.as_ref().map(|s| s.parse::<IntegratorKind>().map_err(|e| anyhow::anyhow!("--integrator: {e}"))).transpose()?,
            accel: self.accel.as_ref().map(parse_accel).transpose()?,
            seed: self.seed,
            light_cells: self.light_cells,
            mis_heuristic: self.mis_heuristic.as_ref().map(|s| s.parse::<MisHeuristic>().map_err(|e| anyhow::anyhow!("--mis-heuristic: {e}"))).transpose()?,
            filter: self.filter.as_ref().map(|s| s.parse::<PixelFilter>().map_err(|e| anyhow::anyhow!("--filter: {e}"))).transpose()?,
            ..Overrides::default()
        })
    }

    /// A thread pool of the requested size; scene loading, builds and rendering run in it.
    pub fn pool(&self) -> Result<rayon::ThreadPool> {
        let mut b = rayon::ThreadPoolBuilder::new();
        if let Some(t) = self.threads {
            b = b.num_threads(t as usize);
        }
        Ok(b.build()?)
    }
}

impl SceneArgs {
    pub fn overrides(&self) -> Result<Overrides> {
        Ok(Overrides {
            spp: self.spp,
            light_sampling: self.light_sampling.as_ref().map(|s| s.parse::<LightSampling>().map_err(|e| anyhow::anyhow!("--light-sampling: {e}"))).transpose()?,
            ..self.settings.overrides()?
        })
    }

    pub fn pool(&self) -> Result<rayon::ThreadPool> {
        self.settings.pool()
    }

    pub fn scene_name(&self) -> String {
        self.scene.as_ref().map_or("the default scene".into(), |p| p.display().to_string())
    }

    pub fn load(&self) -> Result<Scene> {
        let o = self.overrides()?;
        Ok(match &self.scene {
            Some(p) => raylab_loader::load_scene_or_mesh(p, &o)?,
            None => raylab_loader::default_scene(&o)?,
        })
    }
}
