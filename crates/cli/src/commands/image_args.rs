//! How commands that write an image turn linear radiance into it (`render`, `merge`).

use std::path::Path;

use anyhow::{anyhow, Result};
use clap::Args;
use raylab_core::Rgb;
use raylab_render::film::image_out::{self as image_io, Tonemap};

#[derive(Args, Clone, Debug, Default)]
pub struct ImageArgs {
    /// Tone map for 8-bit outputs: clamp, reinhard or aces
    #[arg(long, default_value = "clamp")]
    pub tonemap: Tonemap,
    /// Exposure in stops applied before tone mapping (-64 to 64)
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
}

impl ImageArgs {
    /// Checked before any work is done, so a bad value never costs a render.
    pub fn check(&self) -> Result<()> {
        image_io::check_exposure(self.exposure).map_err(|e| anyhow!("--exposure: {e}"))
    }

    pub fn write(&self, path: &Path, width: u32, height: u32, pixels: &[Rgb]) -> Result<()> {
        Ok(image_io::write_image(path, width, height, pixels, self.tonemap, self.exposure)?)
    }
}
