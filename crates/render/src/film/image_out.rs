//! Tone mapping and image writing, beside the film that produces the pixels: PNG (8-bit
//! sRGB, via `image`), OpenEXR (linear float, via `exr`), PFM (linear float) and PPM (binary
//! P6, the seeds' format). Every file is written atomically; every error starts with the path.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use raylab_core::color::linear_to_srgb8;
use raylab_core::Rgb;

use super::atomic::write_atomic;

/// Formats `write_image` can produce, for messages.
pub fn image_format_names() -> &'static str {
    "png, ppm, exr, pfm"
}

/// Exposures beyond ±64 stops scale any radiance a render can produce out of `f32`'s range
/// (2^128 overflows), so they are refused rather than written as inf/NaN or black.
pub const EXPOSURE_LIMIT: f32 = 64.0;

/// Checks an exposure in stops; the message names the valid range.
pub fn check_exposure(exposure: f32) -> Result<(), String> {
    if !exposure.is_finite() || exposure.abs() > EXPOSURE_LIMIT {
        return Err(format!("exposure {exposure} out of range (-{EXPOSURE_LIMIT} to {EXPOSURE_LIMIT} stops)"));
    }
    Ok(())
}

/// An image that could not be read or written.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct ImageError {
    pub path: PathBuf,
    pub message: String,
}

pub(crate) fn err(path: &Path, message: impl Into<String>) -> ImageError {
    ImageError { path: path.to_path_buf(), message: message.into() }
}

/// How linear radiance becomes a displayable value in [0, 1] before sRGB encoding.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tonemap {
    /// Clip at 1 (the classic ray tracer's behaviour).
    #[default]
    Clamp,
    /// `c / (1 + c)` per channel (Reinhard et al. 2002, simple form).
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve.
    Aces,
}

impl Tonemap {
    pub const ALL: [Tonemap; 3] = [Tonemap::Clamp, Tonemap::Reinhard, Tonemap::Aces];

    pub fn name(self) -> &'static str {
        match self {
            Tonemap::Clamp => "clamp",
            Tonemap::Reinhard => "reinhard",
            Tonemap::Aces => "aces",
        }
    }

    /// Maps one linear channel, scaled by `2^exposure`, into [0, 1]. Non-finite values give 0;
    /// values that overflow when exposed saturate at 1.
    pub fn apply(self, v: f32, exposure: f32) -> f32 {
        if !v.is_finite() || v <= 0.0 {
            return 0.0;
        }
        let v = (v * exposure.exp2()).min(f32::MAX);
        match self {
            Tonemap::Clamp => v.min(1.0),
            Tonemap::Reinhard => v / (1.0 + v),
            // The fit is 1 or more from v ≈ 7.24 on; past 1e4 its products would overflow.
            Tonemap::Aces if v > 1e4 => 1.0,
            Tonemap::Aces => ((v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14)).clamp(0.0, 1.0),
        }
    }
}

/// An unknown tone-map name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownTonemap(pub String);

impl fmt::Display for UnknownTonemap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<_> = Tonemap::ALL.iter().map(|t| t.name()).collect();
        write!(f, "unknown tone map `{}` (valid: {})", self.0, names.join(", "))
    }
}

impl std::error::Error for UnknownTonemap {}

impl FromStr for Tonemap {
    type Err = UnknownTonemap;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Tonemap::ALL.into_iter().find(|t| t.name() == s).ok_or_else(|| UnknownTonemap(s.to_string()))
    }
}

fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// 8-bit sRGB bytes (RGB interleaved) after exposure and tone map.
fn to_srgb8(pixels: &[Rgb], tonemap: Tonemap, exposure: f32) -> Vec<u8> {
    pixels.iter().flat_map(|p| [p.x, p.y, p.z]).map(|v| linear_to_srgb8(tonemap.apply(v, exposure))).collect()
}

/// A linear value for the float formats: exposed, non-finite input as 0, overflow saturated.
fn exposed(v: f32, scale: f32) -> f32 {
    if v.is_finite() { (v * scale).clamp(-f32::MAX, f32::MAX) } else { 0.0 }
}

fn check_size(path: &Path, width: u32, height: u32, pixels: &[Rgb]) -> Result<(), ImageError> {
    if pixels.len() != width as usize * height as usize {
        return Err(err(path, format!("{} pixels for a {width}×{height} image", pixels.len())));
    }
    Ok(())
}

/// Encodes an image as PNG bytes (8-bit sRGB).
pub fn encode_png(width: u32, height: u32, pixels: &[Rgb], tonemap: Tonemap, exposure: f32) -> Result<Vec<u8>, ImageError> {
    let path = Path::new("<png>");
    check_size(path, width, height, pixels)?;
    check_exposure(exposure).map_err(|m| err(path, m))?;
    let mut out = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new(&mut out);
    image::ImageEncoder::write_image(encoder, &to_srgb8(pixels, tonemap, exposure), width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| err(path, format!("cannot encode PNG: {e}")))?;
    Ok(out)
}

/// Encodes an image in the format named by `path`'s extension. PNG and PPM get exposure,
/// tone map and sRGB encoding; EXR and PFM keep linear radiance (exposure still scales it).
pub fn encode_image(path: &Path, width: u32, height: u32, pixels: &[Rgb], tonemap: Tonemap, exposure: f32) -> Result<Vec<u8>, ImageError> {
    check_size(path, width, height, pixels)?;
    check_exposure(exposure).map_err(|m| err(path, m))?;
    let scale = exposure.exp2();
    Ok(match extension(path).as_str() {
        "png" => encode_png(width, height, pixels, tonemap, exposure).map_err(|e| err(path, e.message))?,
        "ppm" => {
            let mut out = format!("P6\n{width} {height}\n255\n").into_bytes();
            out.extend(to_srgb8(pixels, tonemap, exposure));
            out
        }
        "pfm" => {
            let mut out = format!("PF\n{width} {height}\n-1.0\n").into_bytes();
            for row in pixels.chunks(width as usize).rev() {
                for p in row {
                    for v in [p.x, p.y, p.z] {
                        out.extend(exposed(v, scale).to_le_bytes());
                    }
                }
            }
            out
        }
        "exr" => {
            use exr::prelude::*;
            let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
                let p = pixels[y * width as usize + x];
                (exposed(p.x, scale), exposed(p.y, scale), exposed(p.z, scale))
            });
            let mut out = std::io::Cursor::new(Vec::new());
            // Sequential: the parallel writer stores chunks in completion order, so the same
            // pixels would give different bytes from run to run.
            Image::from_channels((width as usize, height as usize), channels).write().non_parallel().to_buffered(&mut out).map_err(|e| err(path, format!("cannot encode OpenEXR: {e}")))?;
            out.into_inner()
        }
        other => return Err(err(path, format!("unknown image format `.{other}` (valid: {})", image_format_names()))),
    })
}

/// Writes an image atomically; the extension picks the format (see [`encode_image`]).
pub fn write_image(path: &Path, width: u32, height: u32, pixels: &[Rgb], tonemap: Tonemap, exposure: f32) -> Result<(), ImageError> {
    let bytes = encode_image(path, width, height, pixels, tonemap, exposure)?;
    write_atomic(path, &bytes).map_err(|e| err(path, format!("cannot write: {e}")))
}

/// An AOV (arbitrary output variable) written as a layer of a multi-layer EXR beside the
/// beauty image, as Cycles and Mitsuba 3 write them: one part, the beauty as `R`, `G`, `B`
/// and each AOV's channels prefixed with its name (`albedo.R`, `normal.X`, `depth.Z`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aov {
    /// The first hit's diffuse colour (linear RGB), the `albedo` integrator's.
    Albedo,
    /// The world-space shading normal facing the camera (Cycles' convention), in [-1, 1];
    /// 0 where nothing is hit.
    Normal,
    /// The distance to the first hit along the camera ray, in scene units; 0 where nothing
    /// is hit.
    Depth,
    /// The variance of the pixel's estimate of luminance (sample variance / samples).
    Variance,
}

raylab_core::named_enum!(Aov, "AOV", { Albedo => "albedo", Normal => "normal", Depth => "depth", Variance => "variance" });

impl Aov {
    /// The integrator whose image this AOV decodes; `None` for the variance, which comes
    /// from the beauty render's own sums.
    pub fn integrator(self) -> Option<crate::IntegratorKind> {
        match self {
            Aov::Albedo => Some(crate::IntegratorKind::Albedo),
            Aov::Normal => Some(crate::IntegratorKind::Normals),
            Aov::Depth => Some(crate::IntegratorKind::Depth),
            Aov::Variance => None,
        }
    }

    /// The channel names of its layer (without the layer's name).
    pub fn channels(self) -> &'static [&'static str] {
        match self {
            Aov::Albedo => &["R", "G", "B"],
            Aov::Normal => &["X", "Y", "Z"],
            Aov::Depth => &["Z"],
            Aov::Variance => &["Y"],
        }
    }

    /// The layer's values of one pixel from its integrator's colour (or the variance in `x`):
    /// the `normals` integrator's `0.5 · (n + 1)` decoded to `n`.
    pub fn decode(self, c: Rgb) -> [f32; 3] {
        match self {
            Aov::Normal => (2.0 * c - Rgb::ONE).to_array(),
            _ => c.to_array(),
        }
    }
}

/// One AOV's image, row-major from the top like the beauty's: its integrator's colours as
/// rendered (the variance in `x`).
pub struct AovImage {
    pub aov: Aov,
    pub pixels: Vec<Rgb>,
}

/// Encodes the beauty image (exposed like a plain EXR) and its AOVs (as they are) as one
/// single-part EXR with a layer per AOV; channel names sort within the part as the format
/// requires.
pub fn encode_exr_layers(path: &Path, width: u32, height: u32, beauty: &[Rgb], exposure: f32, aovs: &[AovImage]) -> Result<Vec<u8>, ImageError> {
    use exr::prelude::*;
    check_size(path, width, height, beauty)?;
    check_exposure(exposure).map_err(|m| err(path, m))?;
    let scale = exposure.exp2();
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        channels.push(AnyChannel::new(*name, FlatSamples::F32(beauty.iter().map(|p| exposed(p[c], scale)).collect())));
    }
    for a in aovs {
        check_size(path, width, height, &a.pixels)?;
        if channels.iter().any(|ch| ch.name.to_string().starts_with(&format!("{}.", a.aov.name()))) {
            return Err(err(path, format!("the AOV `{}` is given twice", a.aov)));
        }
        for (c, name) in a.aov.channels().iter().enumerate() {
            let values = a.pixels.iter().map(|p| { let v = a.aov.decode(*p)[c]; if v.is_finite() { v } else { 0.0 } }).collect();
            channels.push(AnyChannel::new(format!("{}.{name}", a.aov.name()).as_str(), FlatSamples::F32(values)));
        }
    }
    let layer = Layer::new((width as usize, height as usize), LayerAttributes::default(), Encoding::SMALL_LOSSLESS, AnyChannels::sort(channels.into()));
    let mut out = std::io::Cursor::new(Vec::new());
    // Sequential, for the same bytes every time (see `encode_image`).
    Image::from_layer(layer).write().non_parallel().to_buffered(&mut out).map_err(|e| err(path, format!("cannot encode OpenEXR: {e}")))?;
    Ok(out.into_inner())
}

/// Writes [`encode_exr_layers`]'s file atomically.
pub fn write_exr_layers(path: &Path, width: u32, height: u32, beauty: &[Rgb], exposure: f32, aovs: &[AovImage]) -> Result<(), ImageError> {
    if extension(path) != "exr" {
        return Err(err(path, "AOVs go into one multi-layer OpenEXR file: give an .exr output"));
    }
    let bytes = encode_exr_layers(path, width, height, beauty, exposure, aovs)?;
    write_atomic(path, &bytes).map_err(|e| err(path, format!("cannot write: {e}")))
}

/// Why writing `integrator`'s image to `path` loses its values, if it does: depth is a
/// distance in scene units, which an 8-bit format clips at 1 (white beyond one unit).
pub fn lossy_output_warning(path: &Path, integrator: crate::IntegratorKind) -> Option<String> {
    let eight_bit = matches!(extension(path).as_str(), "png" | "ppm");
    (eight_bit && integrator == crate::IntegratorKind::Depth).then(|| {
        format!("{}: depth is a distance in scene units, and an 8-bit image clips it at 1 (everything farther than one unit is white): write .exr or .pfm for the distances, or scale them with --exposure -N (2^-N)", path.display())
    })
}

/// Writes 8-bit PNG values `round(255 · v)` with no tone map and no sRGB curve: for data
/// such as normal maps, read back with `srgb = false`.
pub fn write_linear_png(path: &Path, width: u32, height: u32, pixels: &[Rgb]) -> Result<(), ImageError> {
    check_size(path, width, height, pixels)?;
    let bytes: Vec<u8> = pixels.iter().flat_map(|p| [p.x, p.y, p.z]).map(|v| (exposed(v, 1.0).clamp(0.0, 1.0) * 255.0).round() as u8).collect();
    let mut out = Vec::new();
    image::ImageEncoder::write_image(image::codecs::png::PngEncoder::new(&mut out), &bytes, width, height, image::ExtendedColorType::Rgb8).map_err(|e| err(path, format!("cannot encode PNG: {e}")))?;
    write_atomic(path, &out).map_err(|e| err(path, format!("cannot write PNG: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ppm_header_is_the_seeds_p6() {
        let bytes = encode_image(Path::new("t.ppm"), 2, 1, &[Rgb::ONE, Rgb::ZERO], Tonemap::Clamp, 0.0).unwrap();
        assert_eq!(bytes, b"P6\n2 1\n255\n\xff\xff\xff\x00\x00\x00");
    }

    #[test]
    fn exr_bytes_are_the_same_every_time() {
        // Many chunks of noise: a writer that emits chunks in completion order would differ.
        let (w, h) = (97, 301);
        let pixels: Vec<Rgb> = (0..w * h).map(|i| Rgb::new((i as f32 * 0.618).fract(), (i as f32 * 0.414).fract(), i as f32)).collect();
        let first = encode_image(Path::new("t.exr"), w, h, &pixels, Tonemap::Clamp, 0.0).unwrap();
        for _ in 0..8 {
            assert!(encode_image(Path::new("t.exr"), w, h, &pixels, Tonemap::Clamp, 0.0).unwrap() == first);
        }
    }

    #[test]
    fn unknown_formats_and_exposures_are_refused() {
        let e = write_image(Path::new("out.bmp"), 1, 1, &[Rgb::ONE], Tonemap::Clamp, 0.0).unwrap_err();
        assert_eq!(e.to_string(), "out.bmp: unknown image format `.bmp` (valid: png, ppm, exr, pfm)");
        let e = encode_image(Path::new("out.pfm"), 1, 1, &[Rgb::ONE], Tonemap::Clamp, 128.0).unwrap_err();
        assert_eq!(e.to_string(), "out.pfm: exposure 128 out of range (-64 to 64 stops)");
        let e = encode_image(Path::new("out.pfm"), 2, 1, &[Rgb::ONE], Tonemap::Clamp, 0.0).unwrap_err();
        assert_eq!(e.to_string(), "out.pfm: 1 pixels for a 2×1 image");
    }

    #[test]
    fn the_largest_exposure_stays_finite() {
        // 2^64 · 1e30 overflows f32: saturated, never inf or NaN.
        let bytes = encode_image(Path::new("t.pfm"), 1, 1, &[Rgb::new(1e30, 1.0, 0.0)], Tonemap::Clamp, 64.0).unwrap();
        let body = &bytes[bytes.len() - 12..];
        let v: Vec<f32> = body.chunks(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
        assert_eq!(v, vec![f32::MAX, 2f32.powi(64), 0.0]);
        for t in Tonemap::ALL {
            assert_eq!(t.apply(1e30, 64.0), 1.0, "{t:?}");
        }
    }

    #[test]
    fn tonemaps_are_monotone_and_bounded() {
        for t in Tonemap::ALL {
            assert_eq!(t.name().parse::<Tonemap>().unwrap(), t);
            let mut last = 0.0;
            for i in 0..1000 {
                let v = t.apply(i as f32 * 0.05, 0.0);
                assert!((0.0..=1.0).contains(&v) && v >= last, "{t:?}");
                last = v;
            }
            assert_eq!(t.apply(f32::NAN, 0.0), 0.0);
        }
        assert_eq!(Tonemap::Clamp.apply(0.25, 1.0), 0.5);
        assert_eq!(Tonemap::Reinhard.apply(1.0, 0.0), 0.5);
        assert_eq!("gamma".parse::<Tonemap>().unwrap_err().to_string(), "unknown tone map `gamma` (valid: clamp, reinhard, aces)");
    }

    /// Narkowicz 2016, "ACES Filmic Tone Mapping Curve", in f64: x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14).
    fn aces(x: f64) -> f64 {
        (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
    }

    #[test]
    fn tone_maps_at_published_points() {
        // Reinhard et al. 2002, c / (1 + c): 1 → 1/2, 3 → 3/4, 0.25 → 1/5, 9 → 0.9.
        for (v, expected) in [(1.0f32, 0.5f32), (3.0, 0.75), (0.25, 0.2), (9.0, 0.9)] {
            assert!((Tonemap::Reinhard.apply(v, 0.0) - expected).abs() < 1e-6, "Reinhard({v})");
        }
        // ACES(1) = 2.54/3.16 = 0.803 797; ACES(0.18) = 0.0 867/0.324 9 ≈ 0.266 90 (18 % grey);
        // the fit reaches 1 at x = (0.56 + √0.3584)/0.16 ≈ 7.24.
        assert!((Tonemap::Aces.apply(1.0, 0.0) as f64 - 2.54 / 3.16).abs() < 1e-6);
        assert!((Tonemap::Aces.apply(0.18, 0.0) as f64 - 0.180 * (2.51 * 0.18 + 0.03) / (0.18 * (2.43 * 0.18 + 0.59) + 0.14)).abs() < 1e-6);
        assert!((Tonemap::Aces.apply(0.18, 0.0) - 0.266_90).abs() < 1e-4);
        for x in [0.001f32, 0.01, 0.05, 0.3, 0.5, 0.7, 2.0, 5.0, 7.2] {
            assert!((Tonemap::Aces.apply(x, 0.0) as f64 - aces(x as f64)).abs() < 1e-6, "ACES({x}) = {} against {}", Tonemap::Aces.apply(x, 0.0), aces(x as f64));
        }
        assert!(Tonemap::Aces.apply(7.2, 0.0) < 1.0);
        assert_eq!([Tonemap::Aces.apply(7.3, 0.0), Tonemap::Aces.apply(1e4, 0.0), Tonemap::Aces.apply(2e4, 0.0)], [1.0; 3]);
        // Exposure scales by 2^stops before the curve: 0.25 at +2 stops is 1; 4 at −2 is 1.
        for t in Tonemap::ALL {
            assert_eq!(t.apply(0.25, 2.0), t.apply(1.0, 0.0), "{t:?}");
            assert_eq!(t.apply(4.0, -2.0), t.apply(1.0, 0.0), "{t:?}");
            assert_eq!(t.apply(3.0, 1.0), t.apply(6.0, 0.0), "{t:?}");
        }
        assert_eq!(Tonemap::Clamp.apply(0.3, 1.0), 0.6);
        assert_eq!(Tonemap::Reinhard.apply(0.5, 1.0), 0.5);
        // Zero, negative and non-finite radiance give 0; small positive values pass through.
        for t in Tonemap::ALL {
            for v in [0.0, -0.0, -1.0, f32::NEG_INFINITY, f32::INFINITY, f32::NAN] {
                assert_eq!(t.apply(v, 0.0), 0.0, "{t:?}({v})");
            }
        }
        assert_eq!(Tonemap::Clamp.apply(1e-3, 0.0), 1e-3);
        assert!((Tonemap::Reinhard.apply(1e-3, 0.0) - 1e-3 / 1.001).abs() < 1e-9);
    }

    #[test]
    fn exposures_beyond_64_stops_or_not_finite_are_refused() {
        for e in [64.0f32, -64.0, 0.0, 63.5] {
            assert_eq!(check_exposure(e), Ok(()), "{e}");
        }
        for e in [64.001f32, -64.001, 128.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert_eq!(check_exposure(e), Err(format!("exposure {e} out of range (-64 to 64 stops)")), "{e}");
        }
    }

    /// Decodes 8-bit RGB PNG bytes with the `image` crate's decoder: (width, height, bytes).
    fn png_codes(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
        let img = image::load_from_memory(bytes).unwrap().to_rgb8();
        (img.width(), img.height(), img.into_raw())
    }

    #[test]
    fn png_codes_are_tone_mapped_then_srgb_encoded() {
        // Reinhard: 1 → 0.5 → sRGB 0.735 4 → 188 (IEC 61966-2-1); 3 → 0.75 → 0.880 8 → 225;
        // 0.25 → 0.2 → 0.484 5 → 124; 0 → 0. Three columns, two rows, in order.
        let pixels = [Rgb::new(1.0, 3.0, 0.0), Rgb::new(0.25, 1.0, 0.0), Rgb::ZERO, Rgb::ONE, Rgb::splat(3.0), Rgb::new(0.0, 0.0, 0.25)];
        let (w, h, codes) = png_codes(&encode_png(3, 2, &pixels, Tonemap::Reinhard, 0.0).unwrap());
        assert_eq!((w, h), (3, 2));
        assert_eq!(codes, [188, 225, 0, 124, 188, 0, 0, 0, 0, 188, 188, 188, 225, 225, 225, 0, 0, 124]);
        // Through `encode_image` and a `.png` path, with one stop of exposure: 0.5 → 1 → 188.
        let (_, _, codes) = png_codes(&encode_image(Path::new("t.png"), 1, 1, &[Rgb::splat(0.5)], Tonemap::Reinhard, 1.0).unwrap());
        assert_eq!(codes, [188, 188, 188]);
        assert_eq!(encode_png(2, 2, &pixels, Tonemap::Clamp, 0.0).unwrap_err().to_string(), "<png>: 6 pixels for a 2×2 image");
        assert_eq!(encode_png(1, 1, &[Rgb::ONE], Tonemap::Clamp, f32::NAN).unwrap_err().to_string(), "<png>: exposure NaN out of range (-64 to 64 stops)");
    }

    #[test]
    fn linear_png_holds_round_255_v() {
        // round(255 · v) with no curve: 0.5 → 127.5 → 128, 0.2 → 51, 1 → 255; out of [0, 1]
        // clamped; NaN as 0.
        let path = std::env::temp_dir().join(format!("raylab-image-out-linear-{}.png", std::process::id()));
        write_linear_png(&path, 2, 1, &[Rgb::new(0.5, 0.2, 1.0), Rgb::new(1.5, -1.0, f32::NAN)]).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(png_codes(&bytes), (2, 1, vec![128, 51, 255, 255, 0, 0]));
        assert_eq!(write_linear_png(&path, 3, 1, &[Rgb::ONE]).unwrap_err().to_string(), format!("{}: 1 pixels for a 3×1 image", path.display()));
    }

    #[test]
    fn float_formats_keep_each_pixel_in_place() {
        // 3 × 2, top row first in memory; every channel a different number.
        let pixels: Vec<Rgb> = (0..6).map(|i| Rgb::new(i as f32, 10.0 + i as f32, 100.0 + i as f32)).collect();
        let c = read_channels(&encode_image(Path::new("t.exr"), 3, 2, &pixels, Tonemap::Aces, 0.0).unwrap());
        assert_eq!(c["R"], [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(c["G"], [10.0, 11.0, 12.0, 13.0, 14.0, 15.0]);
        assert_eq!(c["B"], [100.0, 101.0, 102.0, 103.0, 104.0, 105.0]);
        // PFM: the bottom row first, little endian (scale −1.0), exposure −1 halving.
        let bytes = encode_image(Path::new("T.PFM"), 3, 2, &pixels, Tonemap::Aces, -1.0).unwrap();
        let mut expected = b"PF\n3 2\n-1.0\n".to_vec();
        for i in [3, 4, 5, 0, 1, 2] {
            for v in [i as f32, 10.0 + i as f32, 100.0 + i as f32] {
                expected.extend((v / 2.0).to_le_bytes());
            }
        }
        assert_eq!(bytes, expected);
        // PPM: the header, then the top row first.
        let bytes = encode_image(Path::new("t.ppm"), 1, 2, &[Rgb::ONE, Rgb::ZERO], Tonemap::Clamp, 0.0).unwrap();
        assert_eq!(bytes, b"P6\n1 2\n255\n\xff\xff\xff\x00\x00\x00");
    }

    /// The channels of a multi-layer EXR, read back with the exr crate: name -> values.
    fn read_channels(bytes: &[u8]) -> std::collections::BTreeMap<String, Vec<f32>> {
        use exr::prelude::*;
        let image = read().no_deep_data().largest_resolution_level().all_channels().first_valid_layer().all_attributes().from_buffered(std::io::Cursor::new(bytes)).unwrap();
        image.layer_data.channel_data.list.iter().map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect())).collect()
    }

    #[test]
    fn a_layer_per_aov_beside_the_beauty() {
        let beauty = [Rgb::new(1.0, 2.0, 3.0), Rgb::ZERO];
        let aovs = [
            AovImage { aov: Aov::Normal, pixels: vec![Rgb::new(0.5, 1.0, 0.5), Rgb::splat(0.5)] },
            AovImage { aov: Aov::Variance, pixels: vec![Rgb::new(0.25, 0.0, 0.0), Rgb::ZERO] },
        ];
        let c = read_channels(&encode_exr_layers(Path::new("t.exr"), 2, 1, &beauty, 1.0, &aovs).unwrap());
        let names: Vec<&str> = c.keys().map(String::as_str).collect();
        assert_eq!(names, ["B", "G", "R", "normal.X", "normal.Y", "normal.Z", "variance.Y"]);
        // The beauty is exposed (one stop: ×2), the AOVs are not; normals decode to [-1, 1].
        assert_eq!((c["R"][0], c["G"][0], c["B"][0]), (2.0, 4.0, 6.0));
        assert_eq!((c["normal.X"].clone(), c["normal.Y"].clone(), c["normal.Z"].clone()), (vec![0.0, 0.0], vec![1.0, 0.0], vec![0.0, 0.0]));
        assert_eq!(c["variance.Y"], [0.25, 0.0]);
        let twice = [AovImage { aov: Aov::Depth, pixels: vec![Rgb::ONE; 2] }, AovImage { aov: Aov::Depth, pixels: vec![Rgb::ONE; 2] }];
        assert_eq!(encode_exr_layers(Path::new("t.exr"), 2, 1, &beauty, 0.0, &twice).unwrap_err().to_string(), "t.exr: the AOV `depth` is given twice");
        assert_eq!(write_exr_layers(Path::new("t.png"), 2, 1, &beauty, 0.0, &[]).unwrap_err().to_string(), "t.png: AOVs go into one multi-layer OpenEXR file: give an .exr output");
        assert_eq!("normals".parse::<Aov>().unwrap_err(), "unknown AOV `normals` (valid: albedo, normal, depth, variance)");
    }

    /// A diffuse square of albedo (0.2, 0.4, 0.6) in the plane z = 0 filling the middle of a
    /// 9×9 image, seen from z = 3 along -z: every AOV has a closed form at the centre pixel
    /// (its samples stay within a pixel's half-diagonal, atan(√2 · tan(10°) / 9) = 1.59°, of
    /// the axis, so depth is in [3, 3 / cos 1.59°] = [3, 3.00116]) and at the corners, which miss.
    #[test]
    fn aov_layers_of_a_plane_at_a_known_distance() {
        use crate::{render, Camera, IntegratorKind, Material, RenderSettings, Scene, TexColor, TriangleMesh};
        use raylab_core::Vec3;
        for facing in [1.0f32, -1.0] {
            let camera = Camera::new(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 20.0, 1.0, 0.0, None).unwrap();
            let mut scene = Scene::new(camera, RenderSettings { width: 9, height: 9, spp: 4, ..Default::default() });
            let m = scene.add_material("m", Material::Diffuse { albedo: TexColor::Constant(Rgb::new(0.2, 0.4, 0.6)) });
            // Wound to face the camera, then away from it (a floor seen from below its winding):
            // the normal layer faces the camera either way.
            let corners = [Vec3::new(-0.3, -0.3, 0.0), Vec3::new(0.3, -0.3, 0.0), Vec3::new(0.3, 0.3, 0.0), Vec3::new(-0.3, 0.3, 0.0)];
            let indices = if facing > 0.0 { vec![[0, 1, 2], [0, 2, 3]] } else { vec![[0, 2, 1], [0, 3, 2]] };
            scene.geometry.add_mesh(TriangleMesh { positions: corners.to_vec(), indices, material: m, ..Default::default() });
            scene.build_accel(&raylab_accel::BuildOptions::default());
            let aovs: Vec<AovImage> = [Aov::Albedo, Aov::Normal, Aov::Depth]
                .into_iter()
                .map(|aov| {
                    scene.settings.integrator = aov.integrator().unwrap();
                    AovImage { aov, pixels: render(&scene, &|_| {}).pixels }
                })
                .collect();
            scene.settings.integrator = IntegratorKind::Albedo;
            let beauty = render(&scene, &|_| {}).pixels;
            let c = read_channels(&encode_exr_layers(Path::new("t.exr"), 9, 9, &beauty, 0.0, &aovs).unwrap());
            let (centre, corner) = (4 * 9 + 4, 0);
            assert_eq!([c["albedo.R"][centre], c["albedo.G"][centre], c["albedo.B"][centre]], [0.2, 0.4, 0.6]);
            let n = Vec3::new(c["normal.X"][centre], c["normal.Y"][centre], c["normal.Z"][centre]);
            assert!((n - Vec3::Z).length() < 1e-6, "facing {facing}: normal {n}");
            assert!((3.0..=3.00116).contains(&c["depth.Z"][centre]), "depth {}", c["depth.Z"][centre]);
            assert_eq!([c["normal.X"][corner], c["normal.Y"][corner], c["normal.Z"][corner], c["depth.Z"][corner], c["albedo.R"][corner]], [0.0; 5]);
            assert_eq!(c["R"][centre], 0.2);
        }
    }

    #[test]
    fn depth_to_an_eight_bit_image_is_warned_about() {
        use crate::IntegratorKind;
        assert!(lossy_output_warning(Path::new("d.png"), IntegratorKind::Depth).unwrap().starts_with("d.png: depth is a distance in scene units, and an 8-bit image clips it at 1"));
        assert_eq!(lossy_output_warning(Path::new("d.exr"), IntegratorKind::Depth), None);
        assert_eq!(lossy_output_warning(Path::new("d.png"), IntegratorKind::Albedo), None);
    }
}
