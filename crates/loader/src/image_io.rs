//! Reading images (textures, references): PNG/JPEG (8-bit sRGB, via `image`), OpenEXR
//! (linear half/float, via `exr`), PFM (linear float) and PPM (binary P6). Every error
//! starts with the path. Writing lives beside the film, re-exported here.

use std::path::Path;
use std::str::FromStr;

use raylab_core::color::srgb_to_linear;
use raylab_core::Rgb;

// Tone mapping and image writing moved beside the film (`raylab_render::film::image_out`);
// re-exported here so that existing callers keep compiling.
pub use raylab_render::film::image_out::{encode_image, encode_png, image_format_names, write_image, write_linear_png, ImageError, Tonemap, UnknownTonemap};

fn err(path: &Path, message: impl Into<String>) -> ImageError {
    ImageError { path: path.to_path_buf(), message: message.into() }
}

fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// Reads an image as linear RGB, top row first. 8-bit formats are decoded from sRGB when
/// `srgb` is true (colour maps), taken as linear otherwise (normal maps, masks).
pub fn read_image(path: &Path, srgb: bool) -> Result<(u32, u32, Vec<Rgb>), ImageError> {
    let bytes = crate::files::read_capped(path, crate::files::MAX_DATA_BYTES).map_err(|e| err(path, e.message))?;
    decode_image(path, &bytes, srgb)
}

/// Decodes image bytes; `path` names the format (by extension) and the messages.
pub fn decode_image(path: &Path, bytes: &[u8], srgb: bool) -> Result<(u32, u32, Vec<Rgb>), ImageError> {
    let (w, h, pixels) = match extension(path).as_str() {
        "exr" => read_exr(path, bytes)?,
        "pfm" => read_pfm(path, bytes)?,
        "ppm" => read_ppm(path, bytes, srgb)?,
        _ => read_8bit(path, bytes, srgb)?,
    };
    if w == 0 || h == 0 {
        return Err(err(path, "image has no pixels"));
    }
    if let Some(i) = pixels.iter().position(|p| !p.is_finite()) {
        return Err(err(path, format!("pixel ({}, {}) is not a finite number", i as u32 % w, i as u32 / w)));
    }
    Ok((w, h, pixels))
}

fn read_8bit(path: &Path, bytes: &[u8], srgb: bool) -> Result<(u32, u32, Vec<Rgb>), ImageError> {
    let img = image::load_from_memory(bytes).map_err(|e| err(path, format!("cannot decode image: {e}")))?;
    let rgb = img.to_rgb32f();
    let decode = |v: f32| if srgb { srgb_to_linear(v) } else { v };
    let pixels = rgb.pixels().map(|p| Rgb::new(decode(p[0]), decode(p[1]), decode(p[2]))).collect();
    Ok((rgb.width(), rgb.height(), pixels))
}

/// How many bytes of decoded RGB one byte of OpenEXR can give at most: deflate's ratio
/// (1032:1) times the growth of a 2-byte sample into 12 bytes, rounded up.
const MAX_EXR_EXPANSION: u64 = 1 << 13;

fn read_exr(path: &Path, bytes: &[u8]) -> Result<(u32, u32, Vec<Rgb>), ImageError> {
    use exr::prelude::*;
    // The pixel buffer is sized from the header before any pixel is read, and compression
    // lets a small file announce a huge image: check the announced sizes first.
    let bytes_len = bytes.len();
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false).map_err(|e| err(path, format!("cannot decode OpenEXR: {e}")))?;
    for h in meta.headers.iter() {
        let (w, ht) = (h.layer_size.width(), h.layer_size.height());
        let bytes = (w as u64).checked_mul(ht as u64).and_then(|n| n.checked_mul(std::mem::size_of::<Rgb>() as u64));
        // The compressions the exr crate reads pack at most about 1000:1 (deflate's limit;
        // it reads no DWA), and 2-byte half or single-channel samples grow to 12-byte RGB:
        // a layer beyond this cannot be in the file.
        if bytes.is_none_or(|b| b > (bytes_len as u64).saturating_mul(MAX_EXR_EXPANSION)) {
            return Err(err(path, format!("its {w}×{ht} layer cannot be stored in a file of {bytes_len} bytes")));
        }
        // The same for one block (a tile or a band of scan lines), which the reader
        // decompresses whole: a tile can be far larger than its layer.
        let block = match h.blocks {
            exr::meta::BlockDescription::Tiles(t) => (t.tile_size.width() as u64).checked_mul(t.tile_size.height() as u64),
            exr::meta::BlockDescription::ScanLines => Some(h.compression.scan_lines_per_block() as u64 * w as u64),
        };
        if block.and_then(|px| px.checked_mul(h.channels.bytes_per_pixel as u64)).is_none_or(|b| b > (bytes_len as u64).saturating_mul(MAX_EXR_EXPANSION)) {
            let size = match h.blocks {
                exr::meta::BlockDescription::Tiles(t) => format!("{}×{} tiles", t.tile_size.width(), t.tile_size.height()),
                exr::meta::BlockDescription::ScanLines => format!("blocks of {} scan lines", h.compression.scan_lines_per_block()),
            };
            return Err(err(path, format!("its {size} cannot be stored in a file of {bytes_len} bytes")));
        }
        raylab_render::memory_guard::check(&format!("its {w}×{ht} layer"), bytes).map_err(|e| err(path, e))?;
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |res, _| (res.width(), vec![Rgb::ZERO; res.width() * res.height()]),
            |(w, px): &mut (usize, Vec<Rgb>), pos, (r, g, b, _a): (f32, f32, f32, f32)| px[pos.y() * *w + pos.x()] = Rgb::new(r, g, b),
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| err(path, format!("cannot decode OpenEXR: {e}")))?;
    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    Ok((size.width() as u32, size.height() as u32, pixels))
}

/// Splits the whitespace-separated header tokens of a PPM/PFM (with `#` comments), returning
/// the tokens and the offset of the binary data (after one whitespace byte).
fn netpbm_header(path: &Path, bytes: &[u8], count: usize) -> Result<(Vec<String>, usize), ImageError> {
    let mut tokens = Vec::new();
    let mut i = 0;
    while tokens.len() < count {
        while i < bytes.len() && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        if i < bytes.len() && bytes[i] == b'#' {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        let start = i;
        while i < bytes.len() && !bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        if start == i {
            return Err(err(path, "truncated header"));
        }
        tokens.push(String::from_utf8_lossy(&bytes[start..i]).into_owned());
    }
    Ok((tokens, i + 1))
}

fn header_number<T: FromStr>(path: &Path, token: &str, what: &str) -> Result<T, ImageError> {
    token.parse().map_err(|_| err(path, format!("header: {what} `{token}` is not a valid number")))
}

fn dimensions(path: &Path, tokens: &[String]) -> Result<(u32, u32), ImageError> {
    let w: u32 = header_number(path, &tokens[1], "width")?;
    let h: u32 = header_number(path, &tokens[2], "height")?;
    if w == 0 || h == 0 || w > 1 << 16 || h > 1 << 16 {
        return Err(err(path, format!("header: size {w}x{h} out of range (1..=65536)")));
    }
    Ok((w, h))
}

fn read_pfm(path: &Path, bytes: &[u8]) -> Result<(u32, u32, Vec<Rgb>), ImageError> {
    let (tokens, data) = netpbm_header(path, bytes, 4)?;
    let channels = match tokens[0].as_str() {
        "PF" => 3,
        "Pf" => 1,
        other => return Err(err(path, format!("not a PFM file (magic `{other}`, expected PF or Pf)"))),
    };
    let (w, h) = dimensions(path, &tokens)?;
    let scale: f32 = header_number(path, &tokens[3], "scale")?;
    let little = scale < 0.0;
    let n = w as usize * h as usize * channels;
    let body = bytes.get(data..data + n * 4).ok_or_else(|| err(path, format!("truncated: expected {} bytes of pixels", n * 4)))?;
    let value = |k: usize| {
        let b = [body[4 * k], body[4 * k + 1], body[4 * k + 2], body[4 * k + 3]];
        if little { f32::from_le_bytes(b) } else { f32::from_be_bytes(b) }
    };
    let mut pixels = vec![Rgb::ZERO; w as usize * h as usize];
    // PFM stores the bottom row first.
    for y in 0..h as usize {
        for x in 0..w as usize {
            let k = ((h as usize - 1 - y) * w as usize + x) * channels;
            pixels[y * w as usize + x] = if channels == 3 { Rgb::new(value(k), value(k + 1), value(k + 2)) } else { Rgb::splat(value(k)) };
        }
    }
    Ok((w, h, pixels))
}

fn read_ppm(path: &Path, bytes: &[u8], srgb: bool) -> Result<(u32, u32, Vec<Rgb>), ImageError> {
    let (tokens, data) = netpbm_header(path, bytes, 4)?;
    if tokens[0] != "P6" {
        return Err(err(path, format!("not a binary PPM file (magic `{}`, expected P6)", tokens[0])));
    }
    let (w, h) = dimensions(path, &tokens)?;
    let max: u32 = header_number(path, &tokens[3], "maxval")?;
    if max == 0 || max > 65535 {
        return Err(err(path, format!("header: maxval {max} out of range (1..=65535)")));
    }
    let wide = max > 255;
    let n = w as usize * h as usize * 3;
    let size = if wide { 2 * n } else { n };
    let body = bytes.get(data..data + size).ok_or_else(|| err(path, format!("truncated: expected {size} bytes of pixels")))?;
    let sample = |k: usize| {
        let v = if wide { u16::from_be_bytes([body[2 * k], body[2 * k + 1]]) as f32 } else { body[k] as f32 };
        let v = v / max as f32;
        if srgb { srgb_to_linear(v) } else { v }
    };
    let pixels = (0..w as usize * h as usize).map(|i| Rgb::new(sample(3 * i), sample(3 * i + 1), sample(3 * i + 2))).collect();
    Ok((w, h, pixels))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_png_round_trips_without_srgb() {
        let path = std::env::temp_dir().join(format!("raylab-linear-{}.png", std::process::id()));
        let pixels = vec![Rgb::new(0.5, 0.25, 1.0), Rgb::new(0.0, 0.8, 0.1)];
        write_linear_png(&path, 2, 1, &pixels).unwrap();
        let (w, h, back) = read_image(&path, false).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!((w, h), (2, 1));
        for (a, b) in back.iter().zip(&pixels) {
            assert!((*a - *b).abs().max_element() <= 0.5 / 255.0 + 1e-6, "{a} vs {b}");
        }
    }

    fn gradient(w: u32, h: u32) -> Vec<Rgb> {
        (0..w * h).map(|i| Rgb::new((i % w) as f32 / w as f32, (i / w) as f32 / h as f32, 0.25 + i as f32 * 0.01)).collect()
    }

    #[test]
    fn float_formats_round_trip_exactly() {
        let dir = std::env::temp_dir().join(format!("raylab-image-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let pixels = gradient(7, 5);
        for ext in ["pfm", "exr"] {
            let path = dir.join(format!("t.{ext}"));
            write_image(&path, 7, 5, &pixels, Tonemap::Clamp, 0.0).unwrap();
            let (w, h, back) = read_image(&path, false).unwrap();
            assert_eq!((w, h), (7, 5));
            assert_eq!(back, pixels, "{ext}");
        }
    }

    #[test]
    fn eight_bit_formats_round_trip_to_one_code() {
        let dir = std::env::temp_dir().join(format!("raylab-image-io8-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let pixels: Vec<Rgb> = gradient(6, 4).into_iter().map(|p| p.min(Rgb::ONE)).collect();
        for ext in ["png", "ppm"] {
            let path = dir.join(format!("t.{ext}"));
            write_image(&path, 6, 4, &pixels, Tonemap::Clamp, 0.0).unwrap();
            let (w, h, back) = read_image(&path, true).unwrap();
            assert_eq!((w, h), (6, 4));
            for (a, b) in pixels.iter().zip(&back) {
                assert!((*a - *b).abs().max_element() < 0.01, "{ext}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn errors_name_the_file() {
        let e = write_image(Path::new("out.bmp"), 1, 1, &[Rgb::ONE], Tonemap::Clamp, 0.0).unwrap_err();
        assert_eq!(e.to_string(), "out.bmp: unknown image format `.bmp` (valid: png, ppm, exr, pfm)");
        let e = decode_image(Path::new("x.pfm"), b"PF\n2 2\n-1\n\0\0", false).unwrap_err();
        assert_eq!(e.to_string(), "x.pfm: truncated: expected 48 bytes of pixels");
        let e = decode_image(Path::new("x.ppm"), b"P3\n1 1\n255\n", false).unwrap_err();
        assert_eq!(e.to_string(), "x.ppm: not a binary PPM file (magic `P3`, expected P6)");
        let e = decode_image(Path::new("x.png"), b"garbage", false).unwrap_err();
        assert!(e.to_string().starts_with("x.png: cannot decode image: "), "{e}");
        let nan = [b"PF\n1 1\n-1\n".as_slice(), &f32::NAN.to_le_bytes().repeat(3)].concat();
        let e = decode_image(Path::new("x.pfm"), &nan, false).unwrap_err();
        assert_eq!(e.to_string(), "x.pfm: pixel (0, 0) is not a finite number");
    }
}
