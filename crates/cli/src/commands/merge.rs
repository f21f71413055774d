//! `raylab merge`: joins the films of tiles, crops and sample ranges (`raylab render --tile
//! I/N -o part.film`) into one image, after checking that they are of the same scene,
//! settings and version and cover every pixel and sample exactly once. The result has the
//! same bytes as a single-machine render (see `raylab_render::film`).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use clap::Args;
use raylab_render::film::atomic::check_writable;
use raylab_render::film::image_out as image_io;
use raylab_render::film::{Crop, Film};

use super::image_args::ImageArgs;
use super::render::{read_film, write_film};

#[derive(Args, Clone, Debug)]
pub struct MergeArgs {
    /// Partial films written by `raylab render ... -o PART.film`
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// The merged image (.png, .ppm, .exr, .pfm) or film (.film, which may stay partial)
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub image: ImageArgs,
    /// No summary
    #[arg(short, long)]
    pub quiet: bool,
}

pub fn run(a: &MergeArgs) -> Result<()> {
    let ext = a.output.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let to_film = ext == "film";
    if !to_film && !["png", "ppm", "exr", "pfm"].contains(&ext.as_str()) {
        bail!("{}: unknown output format `.{ext}` (valid: {}, film)", a.output.display(), image_io::image_format_names());
    }
    a.image.check()?;
    check_writable(&a.output).map_err(|e| anyhow!("{e}"))?;
    let start = Instant::now();
    let parts = a.parts.iter().map(|p| read_film(p)).collect::<Result<Vec<_>>>()?;
    let read_s = start.elapsed().as_secs_f64();
    let names: Vec<String> = a.parts.iter().map(|p| p.display().to_string()).collect();
    let merged = Film::merge_all(parts).map_err(|e| anyhow!("{e} (parts: {})", names.join(", ")))?;
    let h = &merged.header;
    if !to_film && !merged.is_complete() {
        let full = Crop::full(h.width, h.height);
        let s = merged.samples();
        bail!(
            "the parts do not make the whole image: they cover pixels {} of {full} and samples {}..{} of 0..{} (write a .film to keep a partial merge)",
            merged.crop, s.start, s.end, h.spp
        );
    }
    if to_film {
        write_film(&a.output, &merged)?;
    } else {
        a.image.write(&a.output, h.width, h.height, &merged.resolve())?;
    }
    if !a.quiet {
        let s = merged.samples();
        eprintln!(
            "Merged {} parts into {} ({}×{} pixels {} of {}, samples {}..{} of {}; {:.2} M rays, {} non-finite samples dropped): read in {:.3} s, merged and written in {:.3} s.",
            a.parts.len(),
            a.output.display(),
            merged.crop.width(),
            merged.crop.height(),
            merged.crop,
            Crop::full(h.width, h.height),
            s.start,
            s.end,
            h.spp,
            merged.counters.rays as f64 / 1e6,
            merged.nonfinite_samples,
            read_s,
            start.elapsed().as_secs_f64() - read_s,
        );
    }
    Ok(())
}
