//! `raylab compare`: the error of an image against a reference (MSE, RMSE, relative MSE, PSNR),
//! for measuring convergence, and optionally a false-colour picture of where they differ.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use raylab_lab::compare::{compare, false_colour};
use raylab_loader::image_io::{read_image, write_image, Tonemap};

#[derive(Args, Clone, Debug)]
pub struct CompareArgs {
    /// The image to measure (exr, pfm, png, ppm; 8-bit formats are decoded from sRGB)
    pub a: PathBuf,
    /// The reference image, of the same size
    pub b: PathBuf,
    /// Leave out pixels whose reference luminance exceeds T (visible lights, fireflies)
    #[arg(long, value_name = "T")]
    pub exclude_bright: Option<f32>,
    /// Write a false-colour image of |luminance difference| here (none unless given)
    #[arg(long, value_name = "OUT")]
    pub diff: Option<PathBuf>,
    /// The difference shown at the top of the colour ramp (default: the 99th percentile);
    /// fix it to compare the diff images of a convergence series
    #[arg(long, value_name = "S", requires = "diff")]
    pub diff_scale: Option<f32>,
    /// Print JSON (PSNR is null for identical images)
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &CompareArgs) -> Result<()> {
    for (name, v) in [("--exclude-bright", a.exclude_bright), ("--diff-scale", a.diff_scale)] {
        if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0)) {
            bail!("{name}: expected a finite number above 0, found {v}");
        }
    }
    let (w, h, pa) = read_image(&a.a, true)?;
    let (wb, hb, pb) = read_image(&a.b, true)?;
    if (w, h) != (wb, hb) {
        bail!("{} and {} differ in size: {w}×{h} against {wb}×{hb}", a.a.display(), a.b.display());
    }
    let d = compare(&pa, &pb, w, a.exclude_bright).map_err(|e| anyhow::anyhow!("{} against {}: {e}", a.a.display(), a.b.display()))?;
    let scale = match &a.diff {
        Some(out) => {
            let (pixels, scale) = false_colour(&pa, &pb, a.diff_scale);
            write_image(out, w, h, &pixels, Tonemap::Clamp, 0.0)?;
            Some(scale)
        }
        None => None,
    };
    // JSON has no infinity: identical images have a PSNR of null.
    let psnr = (d.mse > 0.0).then_some(d.psnr_db);
    if a.json {
        println!(
            "{}",
            serde_json::json!({
                "a": a.a, "b": a.b, "width": w, "height": h,
                "mse": d.mse, "rmse": d.rmse, "rel_mse": d.rel_mse, "psnr_db": psnr, "max_abs": d.max_abs,
                "pixels": d.pixels, "excluded": d.excluded, "exclude_bright": a.exclude_bright,
                "diff": a.diff, "diff_scale": scale,
            })
        );
        return Ok(());
    }
    println!("{} against {} ({w}×{h})", a.a.display(), a.b.display());
    println!("  MSE           {:.6e}", d.mse);
    println!("  RMSE          {:.6e}", d.rmse);
    println!("  relative MSE  {:.6e}", d.rel_mse);
    println!("  PSNR          {}", psnr.map_or("∞ (identical)".into(), |p| format!("{p:.2} dB")));
    println!("  max |diff|    {:.6e}", d.max_abs);
    println!("  pixels        {} compared, {} excluded", d.pixels, d.excluded);
    if let (Some(out), Some(s)) = (&a.diff, scale) {
        println!("  diff image    {} (top of the ramp: |Δ luminance| = {s:.4e})", out.display());
    }
    Ok(())
}
