//! Options shared by the commands that load a scene: a flag per setting of the render
//! crate's one settings table (`raylab_render::settings::SETTINGS`, checked by a test here).
//! Named options are clap `ValueEnum`s built from each enum's one list of names, integer
//! options take their ranges from the table, so the help, the parser, the scene files and
//! Python agree.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use raylab_accel::AccelKind;
use raylab_loader::Overrides;
use raylab_render::light::LightSampling as LightSamplingKind;
use raylab_render::filter::PixelFilter;
use raylab_render::integrator::MisHeuristic;
use raylab_render::{IntegratorKind, SamplerKind, Scene};

/// `--accel`'s help: every structure's name, from the one list.
fn accel_help() -> String {
    format!("Acceleration structure by name: {} (none: the brute-force oracle; default bvh8)", AccelKind::names())
}

/// A clap parser for the integer setting `key`, in the settings table's range.
fn ranged(key: &str) -> clap::builder::RangedI64ValueParser<u32> {
    let (min, max) = raylab_render::settings::spec(key).and_then(|s| s.range()).expect("an integer setting");
    clap::value_parser!(u32).range(min as i64..=max as i64)
}

#[derive(Args, Clone, Debug, Default)]
pub struct SceneArgs {
    /// Scene file (.toml, .pbrt) or bare mesh (.obj, .ply, gzipped or not); the embedded default scene when omitted
    pub scene: Option<PathBuf>,
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// Samples per pixel (the jittered sampler rounds up to a square number, and says so)
    #[arg(long, value_parser = ranged("spp"))]
    pub spp: Option<u32>,
    /// Area-light sampling of direct and path
    #[arg(long, value_enum)]
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
    #[arg(long, value_parser = ranged("width"))]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene's)
    #[arg(long, value_parser = ranged("height"))]
    pub height: Option<u32>,
    /// Pixel sampler (jittered: stratified; sobol: scrambled low-discrepancy)
    #[arg(long, value_enum)]
    pub sampler: Option<SamplerKind>,
    /// Maximum number of path segments from the camera
    #[arg(long, value_parser = ranged("max_depth"))]
    pub max_depth: Option<u32>,
    /// Integrator (lighting: whitted, direct, path; AOVs: normals, albedo, depth; statistics: heatmap, heatmap-tests)
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorKind>,
    /// Acceleration structure by name (`none` is the brute-force oracle)
    #[arg(long, help = accel_help())]
    pub accel: Option<String>,
    /// Largest leaf of the acceleration structure's build (default 8)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=255))]
    pub max_leaf_size: Option<u32>,
    /// Bins per axis of the binned SAH builders (default 16; small nodes of the binned SAH use fewer: 4 + n/20)
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=1024))]
    pub bins: Option<u32>,
    /// Builder under bvh, bvh4 and bvh8, as Embree's quality: low (LBVH, fastest build), medium (binned SAH, the default), high (SBVH with spatial splits, best tree); see docs/performance.md
    #[arg(long, value_enum)]
    pub build_quality: Option<raylab_accel::BuildQuality>,
    /// Pixel reconstruction filter
    #[arg(long, value_enum)]
    pub filter: Option<PixelFilter>,
    /// MIS weights of light and BSDF samples (default power)
    #[arg(long, value_enum)]
    pub mis_heuristic: Option<MisHeuristic>,
    /// Cells per side of the `cells` light-sampling grid (1 to 16; default 8)
    #[arg(long, value_parser = ranged("light_cells"))]
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

#[cfg(test)]
mod tests {
    use clap::{Args, Command};
    use raylab_render::settings::{SettingKind, SETTINGS};

    /// The settings table drives the flags: each key has one, with the table's names or range.
    #[test]
    fn every_setting_has_a_flag_with_the_tables_names_and_range() {
        let cmd = super::SceneArgs::augment_args(Command::new("render"));
        let parses = |flag: &str, value: &str| cmd.clone().try_get_matches_from(["render", flag, value]).is_ok();
        for spec in SETTINGS {
            let flag = spec.flag();
            let arg = cmd.get_arguments().find(|a| a.get_long() == Some(&flag[2..])).unwrap_or_else(|| panic!("no flag {flag} for the setting `{}`", spec.key));
            match spec.kind {
                // `--accel` parses by name itself, for its message listing the valid ones.
                SettingKind::Name(names) if spec.key == "accel" => {
                    for name in names().split(", ") {
                        let a = super::SceneArgs { settings: super::SettingsArgs { accel: Some(name.into()), ..Default::default() }, ..Default::default() };
                        assert_eq!(a.overrides().unwrap().accel.unwrap().name(), name);
                    }
                }
                SettingKind::Name(names) => {
                    let values: Vec<String> = arg.get_possible_values().iter().map(|p| p.get_name().to_string()).collect();
                    assert_eq!(values.join(", "), names(), "{flag}");
                }
                SettingKind::Integer { min, max } => {
                    assert!(parses(&flag, &min.to_string()) && parses(&flag, &max.to_string()), "{flag}");
                    assert!(!parses(&flag, &(max as u128 + 1).to_string()), "{flag} accepts {}", max as u128 + 1);
                    assert!(min == 0 || !parses(&flag, &(min - 1).to_string()), "{flag} accepts {}", min - 1);
                }
            }
        }
    }
}
