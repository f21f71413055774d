//! `raylab converge`: renders a scene with each light-sampling strategy at a series of sample
//! counts, measures each render against a reference, and writes a CSV, an HTML page with
//! log–log charts and fitted slopes, and the final images.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use clap::Args;
use raylab_lab::converge::{csv, html, measure, render_with, spp_slope, strategies, ConvergencePoint, LabelledImage, Study, REFERENCE_SEED_XOR};
use raylab_loader::image_io::{encode_png, read_image, write_image, Tonemap};
use raylab_loader::Overrides;
use raylab_render::light::LightSampling;
use raylab_render::{IntegratorKind, Scene};

use super::scene_args::SettingsArgs;

#[derive(Args, Clone, Debug)]
pub struct ConvergeArgs {
    /// Scene file (TOML) or bare mesh (OBJ, .obj.gz)
    pub scene: PathBuf,
    #[command(flatten)]
    pub settings: SettingsArgs,
    /// The reference image (exr, pfm, png; the size of the renders); without it, one is
    /// rendered with mis at --reference-spp and written to DIR/reference.exr
    #[arg(long, value_name = "FILE")]
    pub reference: Option<PathBuf>,
    /// Samples per pixel of the rendered reference
    #[arg(long, value_name = "N", default_value_t = 4096, value_parser = clap::value_parser!(u32).range(1..=1048576))]
    pub reference_spp: u32,
    /// Light-sampling strategies to measure, comma-separated
    #[arg(long, value_name = "LIST", default_value = "uniform,solid-angle,bsdf,mis")]
    pub strategies: String,
    /// Samples per pixel to measure, comma-separated (rendered in increasing order)
    #[arg(long, value_name = "LIST", default_value = "1,2,4,8,16,32,64,128,256")]
    pub spp: String,
    /// Stop a strategy's series after the first render that takes longer than S seconds
    /// (that render is still measured); the other strategies go on
    #[arg(long, value_name = "S")]
    pub time_budget: Option<f64>,
    /// Leave out pixels whose reference luminance exceeds T (visible lights, fireflies)
    #[arg(long, value_name = "T")]
    pub exclude_bright: Option<f32>,
    /// Output folder (created): convergence.csv, convergence.html, <strategy>_<spp>.exr at each
    /// strategy's highest spp, and reference.exr when rendered
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
}

/// Parses a comma-separated list, naming the option in errors.
fn list<T>(option: &str, s: &str, parse: impl Fn(&str) -> Result<T, String>) -> Result<Vec<T>> {
    s.split(',').map(|item| parse(item.trim()).map_err(|e| anyhow!("{option}: {e}"))).collect()
}

pub fn run(a: &ConvergeArgs) -> Result<()> {
    let strategy_list = list("--strategies", &a.strategies, str::parse::<LightSampling>)?;
    let mut spps = list("--spp", &a.spp, |s| s.parse::<u32>().ok().filter(|n| (1..=1 << 20).contains(n)).ok_or_else(|| format!("expected whole numbers from 1 to 1048576, found `{s}`")))?;
    spps.sort_unstable();
    spps.dedup();
    if let Some(t) = a.time_budget.filter(|t| !(t.is_finite() && *t > 0.0)) {
        bail!("--time-budget: expected a finite number of seconds above 0, found {t}");
    }
    if let Some(t) = a.exclude_bright.filter(|t| !(t.is_finite() && *t > 0.0)) {
        bail!("--exclude-bright: expected a finite number above 0, found {t}");
    }
    a.settings.pool()?.install(|| {
        // spp 1 suits every sampler; the study sets its own counts.
        let mut scene = raylab_loader::load_scene_or_mesh(&a.scene, &Overrides { spp: Some(1), ..a.settings.overrides()? })?;
        let s = &scene.settings;
        if !matches!(s.integrator, IntegratorKind::Direct | IntegratorKind::Path) {
            bail!("light-sampling strategies differ only under the direct and path integrators; {} uses {} (pass --integrator direct or path)", a.scene.display(), s.integrator);
        }
        for &n in &spps {
            s.sampler.check_spp(n).map_err(|e| anyhow!("--spp: {e}"))?;
        }
        if a.reference.is_none() {
            s.sampler.check_spp(a.reference_spp).map_err(|e| anyhow!("--reference-spp: {e}"))?;
        }
        let (w, h, seed) = (s.width, s.height, s.seed);
        std::fs::create_dir_all(&a.output).map_err(|e| anyhow!("cannot create {}: {e}", a.output.display()))?;
        let (reference, reference_label) = match &a.reference {
            Some(path) => {
                let (rw, rh, pixels) = read_image(path, true)?;
                if (rw, rh) != (w, h) {
                    bail!("the reference {} is {rw}×{rh} but the renders are {w}×{h} (set --width and --height)", path.display());
                }
                (pixels, format!("reference ({})", path.display()))
            }
            None => {
                // Another seed: a reference sharing the renders' random streams would correlate
                // with them and understate their error.
                let pixels = render_with(&mut scene, LightSampling::Mis, a.reference_spp, seed ^ REFERENCE_SEED_XOR).pixels;
                scene.settings.seed = seed;
                let path = a.output.join("reference.exr");
                write_image(&path, w, h, &pixels, Tonemap::Clamp, 0.0)?;
                println!("no --reference given: rendered one with mis at {} spp ({})", a.reference_spp, path.display());
                (pixels, format!("reference (mis, {} spp, another seed)", a.reference_spp))
            }
        };
        println!("{:<12} {:>7} {:>9} {:>12} {:>12}", "strategy", "spp", "seconds", "MSE", "relMSE");
        let study = Study { strategies: &strategy_list, spps: &spps, time_budget: a.time_budget, exclude_bright: a.exclude_bright };
        let mut show = |p: &ConvergencePoint| println!("{:<12} {:>7} {:>9.3} {:>12.4e} {:>12.4e}", p.strategy, p.spp, p.seconds, p.mse, p.rel_mse);
        let (points, finals) = measure(&mut scene, &reference, &study, &mut show, &|| false).map_err(|e| anyhow!(e))?;
        let mut images = Vec::new();
        for f in &finals {
            write_image(&a.output.join(format!("{}_{}.exr", f.strategy, f.spp)), w, h, &f.pixels, Tonemap::Clamp, 0.0)?;
            images.push(LabelledImage { label: format!("{}, {} spp", f.strategy, f.spp), png: encode_png(w, h, &f.pixels, Tonemap::Clamp, 0.0)? });
        }
        images.push(LabelledImage { label: reference_label.clone(), png: encode_png(w, h, &reference, Tonemap::Clamp, 0.0)? });
        println!("slope of ln MSE against ln spp (least squares; -1 for independent samples):");
        for name in strategies(&points) {
            println!("  {name:<12} {}", spp_slope(&points, name).map_or("(too few points)".into(), |s| format!("{s:.3}")));
        }
        write(&a.output.join("convergence.csv"), csv(&points))?;
        let intro = intro(a, &scene, &reference_label);
        write(&a.output.join("convergence.html"), html(&intro, &points, &images))?;
        Ok(())
    })
}

fn write(path: &Path, text: String) -> Result<()> {
    raylab_render::film::atomic::write_atomic(path, text).map_err(|e| anyhow!("cannot write {}: {e}", path.display()))
}

/// The page's description of the study.
fn intro(a: &ConvergeArgs, scene: &Scene, reference: &str) -> String {
    let s = &scene.settings;
    let mut t = format!(
        "{} at {}×{}, integrator {}, sampler {}, max depth {}, seed {}; against {}. Slopes are least-squares fits of ln MSE against ln spp: \
         −1 for an unbiased estimator with independent samples, steeper for stratified and Sobol samples on smooth integrands.",
        a.scene.display(),
        s.width,
        s.height,
        s.integrator,
        s.sampler,
        s.max_depth,
        s.seed,
        reference
    );
    if let Some(b) = a.exclude_bright {
        t.push_str(&format!(" Pixels with reference luminance above {b} are left out."));
    }
    if let Some(b) = a.time_budget {
        t.push_str(&format!(" A strategy's series stops after its first render over {b} s."));
    }
    t
}
