//! Options shared by the commands that load a scene. Every named option's values come from
//! the enum's own list of names (`ALL`), so the help, the parser and the scene files agree.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use raylab_accel::AccelKind;
use raylab_loader::Overrides;
use raylab_render::light::LightSampling as LightSamplingKind;
use raylab_render::filter::PixelFilter;
use raylab_render::integrator::MisHeuristic;
use raylab_render::{IntegratorKind, SamplerKind, Scene};

/// A clap parser accepting exactly the names of a named option enum (`SamplerKind::ALL`, ...).
macro_rules! named {
    ($ty:ty) => {
        clap::builder::TypedValueParser::map(clap::builder::PossibleValuesParser::new(<$ty>::ALL.iter().map(|k| k.name())), |s| s.parse::<$ty>().expect("a possible value is a valid name"))
    };
}

#[derive(Args, Clone, Debug, Default)]
pub struct SceneArgs {
    /// Scene file (.toml, .pbrt) or bare mesh (.obj, .ply, gzipped or not); the embedded default scene when omitted
    pub scene: Option<PathBuf>,
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// Samples per pixel (the jittered sampler rounds up to a square number, and says so)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1048576))]
    pub spp: Option<u32>,
    /// Area-light sampling of direct and path
    #[arg(long, value_parser = named!(LightSamplingKind))]
    pub light_sampling: Option<LightSamplingKind>,
    /// Warn about and skip what raylab does not support in a pbrt-v4 scene, instead of failing
    #[arg(long)]
    pub lenient: bool,
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
    /// Pixel sampler (jittered: stratified; sobol: scrambled low-discrepancy)
    #[arg(long, value_parser = named!(SamplerKind))]
    pub sampler: Option<SamplerKind>,
    /// Maximum number of path segments from the camera
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub max_depth: Option<u32>,
    /// Integrator (lighting: whitted, direct, path; AOVs: normals, albedo, depth; statistics: heatmap, heatmap-tests)
    #[arg(long, value_parser = named!(IntegratorKind))]
    pub integrator: Option<IntegratorKind>,
    /// Acceleration structure by name: none (the brute-force oracle), bvh, kdtree, grid, sbvh, ... (an unknown name lists them all)
    #[arg(long)]
    pub accel: Option<String>,
    /// Largest leaf of the acceleration structure's build (default 8)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=255))]
    pub max_leaf_size: Option<u32>,
    /// Bins of the binned SAH builders (default 16)
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=1024))]
    pub bins: Option<u32>,
    /// Builder under bvh, bvh4 and bvh8, as Embree's quality: low (LBVH, fastest build), medium (binned SAH, the default), high (SBVH with spatial splits, best tree); see docs/performance.md
    #[arg(long, value_parser = named!(raylab_accel::BuildQuality))]
    pub build_quality: Option<raylab_accel::BuildQuality>,
    /// Pixel reconstruction filter
    #[arg(long, value_parser = named!(PixelFilter))]
    pub filter: Option<PixelFilter>,
    /// MIS weights of light and BSDF samples (default power)
    #[arg(long, value_parser = named!(MisHeuristic))]
    pub mis_heuristic: Option<MisHeuristic>,
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
        let build = (self.max_leaf_size.is_some() || self.bins.is_some() || self.build_quality.is_some()).then(|| {
            let mut b = raylab_accel::BuildOptions::default();
            b.max_leaf_size = self.max_leaf_size.map_or(b.max_leaf_size, |n| n as usize);
            b.bins = self.bins.map_or(b.bins, |n| n as usize);
            b.quality = self.build_quality.unwrap_or(b.quality);
            b
        });
        Ok(Overrides {
            width: self.width,
            height: self.height,
            max_depth: self.max_depth,
            sampler: self.sampler,
            integrator: self.integrator,
            accel: self.accel.as_deref().map(|s| s.parse::<AccelKind>().map_err(|e| anyhow::anyhow!("--accel: {e}"))).transpose()?,
            seed: self.seed,
            light_cells: self.light_cells,
            mis_heuristic: self.mis_heuristic,
            filter: self.filter,
            build,
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
            light_sampling: self.light_sampling,
            lenient: self.lenient,
            ..self.settings.overrides()?
        })
    }

    pub fn pool(&self) -> Result<rayon::ThreadPool> {
        self.settings.pool()
    }

    pub fn scene_name(&self) -> String {
        self.scene.as_ref().map_or("the default scene".into(), |p| p.display().to_string())
    }

    /// Loads the scene, and warns (once, on stderr) when its render is certain to be black.
    pub fn load(&self) -> Result<Scene> {
        let o = self.overrides()?;
        let scene = match &self.scene {
            Some(p) => raylab_loader::load_scene_or_mesh(p, &o)?,
            None => raylab_loader::default_scene(&o)?,
        };
        for w in raylab_loader::black_render_warnings(&scene) {
            eprintln!("warning: {w}");
        }
        Ok(scene)
    }
}
