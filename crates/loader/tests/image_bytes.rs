//! The float image codecs against bytes written out here from the format specifications
//! (PFM: Debevec's Portable Float Map, bottom row first; OpenEXR: "The OpenEXR File
//! Layout", an uncompressed scan-line file), not against our own writer or reader only.

use std::path::Path;

use raylab_core::Rgb;
use raylab_loader::image_io::{decode_image, write_image, Tonemap};

fn le(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn be(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_be_bytes()).collect()
}

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("raylab-image-bytes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn pfm_writer_emits_the_specified_bytes() {
    // 2 × 2, top row (1,2,3) (4,5,6), bottom row (7,8,9) (10,11,12); exposure +1 doubles.
    let pixels = [Rgb::new(1.0, 2.0, 3.0), Rgb::new(4.0, 5.0, 6.0), Rgb::new(7.0, 8.0, 9.0), Rgb::new(10.0, 11.0, 12.0)];
    let path = temp("w.pfm");
    write_image(&path, 2, 2, &pixels, Tonemap::Reinhard, 1.0).unwrap();
    // Header "PF", size, negative scale = little endian; then the bottom row first.
    let mut expected = b"PF\n2 2\n-1.0\n".to_vec();
    expected.extend(le(&[14.0, 16.0, 18.0, 20.0, 22.0, 24.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0]));
    assert_eq!(std::fs::read(&path).unwrap(), expected);
    // Non-finite values are written as 0 rather than poisoning the file.
    write_image(&path, 1, 1, &[Rgb::new(f32::NAN, f32::INFINITY, 0.5)], Tonemap::Clamp, 0.0).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), [b"PF\n1 1\n-1.0\n".to_vec(), le(&[0.0, 0.0, 0.5])].concat());
}

#[test]
fn pfm_reader_decodes_hand_written_files() {
    // Big endian (positive scale), 2 × 2, bottom row first in the file.
    let bytes = [b"PF\n2 2\n1.0\n".to_vec(), be(&[7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0])].concat();
    let (w, h, px) = decode_image(Path::new("be.pfm"), &bytes, false).unwrap();
    assert_eq!((w, h), (2, 2));
    assert_eq!(px, vec![Rgb::new(1.0, 2.0, 3.0), Rgb::new(4.0, 5.0, 6.0), Rgb::new(7.0, 8.0, 9.0), Rgb::new(10.0, 11.0, 12.0)]);
    // Greyscale "Pf", little endian, 1 × 2: each value fills all three channels.
    let bytes = [b"Pf\n1 2\n-1\n".to_vec(), le(&[0.25, -3.5])].concat();
    let (w, h, px) = decode_image(Path::new("grey.pfm"), &bytes, false).unwrap();
    assert_eq!((w, h, px), (1, 2, vec![Rgb::splat(-3.5), Rgb::splat(0.25)]));
    // A bad magic is named.
    let e = decode_image(Path::new("x.pfm"), b"PX\n1 1\n-1\n\0\0\0\0", false).unwrap_err();
    assert_eq!(e.to_string(), "x.pfm: not a PFM file (magic `PX`, expected PF or Pf)");
}

/// One header attribute: name, type, byte size, value.
fn attribute(out: &mut Vec<u8>, name: &str, kind: &str, value: &[u8]) {
    out.extend(name.as_bytes());
    out.push(0);
    out.extend(kind.as_bytes());
    out.push(0);
    out.extend((value.len() as i32).to_le_bytes());
    out.extend(value);
}

fn i32s(values: &[i32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A 2 × 2 uncompressed scan-line OpenEXR file, written byte by byte: channels B (HALF),
/// G and R (FLOAT), in the alphabetical order the format requires.
fn hand_written_exr() -> Vec<u8> {
    let mut f = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
    let mut chlist = Vec::new();
    for (name, pixel_type) in [("B", 1i32), ("G", 2), ("R", 2)] {
        chlist.extend(name.as_bytes());
        chlist.push(0);
        chlist.extend(pixel_type.to_le_bytes());
        chlist.extend([0, 0, 0, 0]); // pLinear, reserved
        chlist.extend(i32s(&[1, 1])); // x and y sampling
    }
    chlist.push(0);
    attribute(&mut f, "channels", "chlist", &chlist);
    attribute(&mut f, "compression", "compression", &[0]);
    attribute(&mut f, "dataWindow", "box2i", &i32s(&[0, 0, 1, 1]));
    attribute(&mut f, "displayWindow", "box2i", &i32s(&[0, 0, 1, 1]));
    attribute(&mut f, "lineOrder", "lineOrder", &[0]);
    attribute(&mut f, "pixelAspectRatio", "float", &1.0f32.to_le_bytes());
    attribute(&mut f, "screenWindowCenter", "v2f", &le(&[0.0, 0.0]));
    attribute(&mut f, "screenWindowWidth", "float", &1.0f32.to_le_bytes());
    f.push(0);
    // Offset table: one block per line; each block is y, size, then B, G, R of the line.
    let line_bytes = 2 * (2 + 4 + 4);
    let first = f.len() + 2 * 8;
    for y in 0..2 {
        f.extend(((first + y * (8 + line_bytes)) as u64).to_le_bytes());
    }
    // Half floats: 0x3C00 = 1, 0x3800 = 0.5, 0x4000 = 2, 0xC000 = −2.
    let lines: [([u16; 2], [f32; 2], [f32; 2]); 2] = [([0x3C00, 0x3800], [0.125, 0.25], [3.0, 4.0]), ([0x4000, 0xC000], [6.0, 7.0], [8.5, 9.5])];
    for (y, (b, g, r)) in lines.iter().enumerate() {
        f.extend(i32s(&[y as i32, line_bytes as i32]));
        f.extend(b.iter().flat_map(|v| v.to_le_bytes()));
        f.extend(le(g));
        f.extend(le(r));
    }
    f
}

#[test]
fn exr_reader_decodes_a_hand_written_file() {
    let (w, h, px) = decode_image(Path::new("hand.exr"), &hand_written_exr(), false).unwrap();
    assert_eq!((w, h), (2, 2));
    assert_eq!(px, vec![Rgb::new(3.0, 0.125, 1.0), Rgb::new(4.0, 0.25, 0.5), Rgb::new(8.5, 6.0, 2.0), Rgb::new(9.5, 7.0, -2.0)]);
    // Cut inside the pixels: an error naming the file, never a panic.
    let bytes = hand_written_exr();
    let e = decode_image(Path::new("cut.exr"), &bytes[..bytes.len() - 10], false).unwrap_err();
    assert!(e.to_string().starts_with("cut.exr: cannot decode OpenEXR: "), "{e}");
}

#[test]
fn exr_writer_stores_linear_float_rgb() {
    // Read back with the `exr` crate's generic reader (not our `rgba_channels` path): the
    // channels and values a third-party reader sees.
    use exr::prelude::*;
    let path = temp("w.exr");
    let pixels = [Rgb::new(0.5, 2.0, 100.0), Rgb::new(f32::NAN, 0.0, 1e-3)];
    write_image(&path, 2, 1, &pixels, Tonemap::Aces, -1.0).unwrap();
    let image = read_all_flat_layers_from_file(&path).unwrap();
    let layer = &image.layer_data[0];
    assert_eq!((layer.size.width(), layer.size.height()), (2, 1));
    let names: Vec<String> = layer.channel_data.list.iter().map(|c| c.name.to_string()).collect();
    assert_eq!(names, ["B", "G", "R"]);
    let channel = |i: usize| match &layer.channel_data.list[i].sample_data {
        FlatSamples::F32(v) => v.clone(),
        other => panic!("channel {i} is not f32: {other:?}"),
    };
    // Exposure −1 halves; no tone map on float output; NaN is written as 0.
    assert_eq!((channel(2), channel(1), channel(0)), (vec![0.25, 0.0], vec![1.0, 0.0], vec![50.0, 5e-4]));
}

/// Found by the `image_exr` fuzz target: a 2 KB file whose header announces a layer of 23 GB
/// of pixels passed the memory guard on a 24 GB machine and was allocated before decoding
/// failed. No compression packs that much into that little.
#[test]
fn an_exr_announcing_more_pixels_than_its_bytes_can_hold_is_refused() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    let bytes = std::fs::read(dir.join("regressions/image_exr/huge-layer-in-tiny-file")).unwrap();
    let e = decode_image(Path::new("x.exr"), &bytes, false).unwrap_err().to_string();
    assert!(e.starts_with("x.exr: its ") && e.ends_with(&format!(" layer cannot be stored in a file of {} bytes", bytes.len())), "{e}");
    // A real (small) EXR still reads.
    let seed = std::fs::read(dir.join("corpus/image_exr/tiny.exr")).unwrap();
    assert_eq!(decode_image(Path::new("x.exr"), &seed, false).unwrap().0, 4);
}

/// Found by the `image_exr` fuzz target: a 557-byte file of a 4×3 layer in 64×8716608 tiles
/// took 6 s (the reader decompresses a block whole). A block is held to the same bound.
#[test]
fn an_exr_whose_tiles_cannot_be_in_its_bytes_is_refused() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    let bytes = std::fs::read(dir.join("regressions/image_exr/huge-tiles-slow")).unwrap();
    let e = decode_image(Path::new("x.exr"), &bytes, false).unwrap_err().to_string();
    assert_eq!(e, "x.exr: its 64×8716608 tiles cannot be stored in a file of 557 bytes");
}

/// IEC 61966-2-1's decoding curve, written out: c/12.92 up to 0.040 45, ((c + 0.055)/1.055)^2.4 above.
fn srgb_decode(c: f64) -> f64 {
    if c <= 0.040_45 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

fn close(got: &[Rgb], expected: &[[f64; 3]]) {
    assert_eq!(got.len(), expected.len());
    for (g, e) in got.iter().zip(expected) {
        for c in 0..3 {
            assert!((g[c] as f64 - e[c]).abs() < 1e-6, "{g} against {e:?}");
        }
    }
}

#[test]
fn ppm_reader_decodes_hand_written_files() {
    // P6 (Netpbm): magic, width, height, maxval as whitespace-separated tokens, `#` comments
    // to the end of a line, then exactly one whitespace byte and the samples, top row first.
    let bytes = [b"P6\n# a comment\n  2\t1 # another\n255\n".as_slice(), &[255, 0, 51, 188, 1, 128]].concat();
    let (w, h, px) = decode_image(Path::new("x.ppm"), &bytes, false).unwrap();
    assert_eq!((w, h), (2, 1));
    close(&px, &[[1.0, 0.0, 0.2], [188.0 / 255.0, 1.0 / 255.0, 128.0 / 255.0]]);
    // The same bytes as sRGB: decoded by the curve (188 → 0.502 9, 51 → 0.033 2, 1 → 1/(255·12.92)).
    let (_, _, px) = decode_image(Path::new("x.ppm"), &bytes, true).unwrap();
    close(&px, &[[1.0, 0.0, srgb_decode(0.2)], [srgb_decode(188.0 / 255.0), 1.0 / 255.0 / 12.92, srgb_decode(128.0 / 255.0)]]);
    assert!((srgb_decode(188.0 / 255.0) - 0.502_886).abs() < 1e-6);
    // A data byte that is whitespace (10, 32) is a sample, not part of the header; so is
    // anything after the pixels (ignored).
    let bytes = [b"P6 1 1 255\n".as_slice(), &[10, 32, 9], b"trailing"].concat();
    let (_, _, px) = decode_image(Path::new("x.ppm"), &bytes, false).unwrap();
    close(&px, &[[10.0 / 255.0, 32.0 / 255.0, 9.0 / 255.0]]);
    // maxval above 255: two bytes per sample, most significant first, scaled by maxval.
    // 500 = 0x01F4, 1000 = 0x03E8, 250 = 0x00FA, 0x0100 = 256, 0x0080 = 128, 0.
    let bytes = [b"P6\n2 1\n1000\n".as_slice(), &[0x01, 0xF4, 0x03, 0xE8, 0x00, 0xFA, 0x01, 0x00, 0x00, 0x80, 0x00, 0x00]].concat();
    let (w, h, px) = decode_image(Path::new("x.ppm"), &bytes, false).unwrap();
    assert_eq!((w, h), (2, 1));
    close(&px, &[[0.5, 1.0, 0.25], [0.256, 0.128, 0.0]]);
    // 256 is the first two-byte maxval, 255 the last one-byte one, 65535 the largest.
    let (_, _, px) = decode_image(Path::new("x.ppm"), &[b"P6 1 1 256\n".as_slice(), &[0x01, 0x00, 0x00, 0x80, 0x00, 0x40]].concat(), false).unwrap();
    close(&px, &[[1.0, 0.5, 0.25]]);
    let (_, _, px) = decode_image(Path::new("x.ppm"), &[b"P6 1 1 65535\n".as_slice(), &[0xFF, 0xFF, 0x80, 0x00, 0x00, 0x01]].concat(), false).unwrap();
    close(&px, &[[1.0, 32768.0 / 65535.0, 1.0 / 65535.0]]);
    // A small maxval scales one-byte samples: 3 of 5.
    let (_, _, px) = decode_image(Path::new("x.ppm"), &[b"P6 1 1 5\n".as_slice(), &[5, 3, 0]].concat(), false).unwrap();
    close(&px, &[[1.0, 0.6, 0.0]]);
}

#[test]
fn netpbm_headers_out_of_range_are_refused_by_name() {
    let e = |name: &str, bytes: &[u8]| decode_image(Path::new(name), bytes, false).unwrap_err().to_string();
    assert_eq!(e("x.ppm", b"P6 1 1 0\n\0\0\0"), "x.ppm: header: maxval 0 out of range (1..=65535)");
    assert_eq!(e("x.ppm", b"P6 1 1 65536\n\0\0\0\0\0\0"), "x.ppm: header: maxval 65536 out of range (1..=65535)");
    assert_eq!(e("x.ppm", b"P6 1 1 255\n\0\0"), "x.ppm: truncated: expected 3 bytes of pixels");
    assert_eq!(e("x.ppm", b"P6 2 1 256\n\0\0\0\0\0\0\0\0\0\0\0"), "x.ppm: truncated: expected 12 bytes of pixels");
    assert_eq!(e("x.ppm", b"P6 2 1"), "x.ppm: truncated header");
    assert_eq!(e("x.ppm", b"P6 2 1 # no maxval\n"), "x.ppm: truncated header");
    // A comment running to the end of the file, and whitespace at its end.
    assert_eq!(e("x.ppm", b"P6 2 1 # no maxval, no newline"), "x.ppm: truncated header");
    assert_eq!(e("x.ppm", b"P6 2 1 \n\t "), "x.ppm: truncated header");
    assert_eq!(e("x.ppm", b"P6 two 1 255\n"), "x.ppm: header: width `two` is not a valid number");
    assert_eq!(e("x.ppm", b"P6 2 -1 255\n"), "x.ppm: header: height `-1` is not a valid number");
    assert_eq!(e("x.pfm", b"PF 1 1 one\n"), "x.pfm: header: scale `one` is not a valid number");
    assert_eq!(e("x.ppm", b"P6 1 1 x\n"), "x.ppm: header: maxval `x` is not a valid number");
    // Sizes: 1 to 65536 on each side.
    for (w, h) in [(0, 1), (1, 0), (65537, 1), (1, 65537)] {
        assert_eq!(e("x.ppm", format!("P6 {w} {h} 255\n").as_bytes()), format!("x.ppm: header: size {w}x{h} out of range (1..=65536)"));
        assert_eq!(e("x.pfm", format!("Pf {w} {h} -1\n").as_bytes()), format!("x.pfm: header: size {w}x{h} out of range (1..=65536)"));
    }
    for (w, h) in [(65536u32, 1u32), (1, 65536)] {
        let bytes = [format!("P6 {w} {h} 255\n").into_bytes(), vec![7; 3 * 65536]].concat();
        let (gw, gh, px) = decode_image(Path::new("x.ppm"), &bytes, false).unwrap();
        assert_eq!((gw, gh, px.len()), (w, h, 65536));
        assert_eq!(px[65535], Rgb::splat(7.0 / 255.0));
        // A PFM of the same size: 4 bytes a sample, one sample a pixel for "Pf".
        let bytes = [format!("Pf {w} {h} -1\n").into_bytes(), le(&[0.5]).repeat(65536)].concat();
        let (gw, gh, px) = decode_image(Path::new("x.pfm"), &bytes, false).unwrap();
        assert_eq!((gw, gh, px[65535]), (w, h, Rgb::splat(0.5)));
    }
}

#[test]
fn pfm_reader_takes_the_byte_order_from_the_scale_sign_and_flips_rows() {
    // 1 × 3 "Pf" (one value a pixel), little endian: file rows bottom to top 1, 2, 3.
    let (w, h, px) = decode_image(Path::new("x.pfm"), &[b"Pf\n1 3\n-2.5\n".as_slice(), &le(&[1.0, 2.0, 3.0])].concat(), false).unwrap();
    assert_eq!((w, h, px), (1, 3, vec![Rgb::splat(3.0), Rgb::splat(2.0), Rgb::splat(1.0)]));
    // 3 × 1 "PF" big endian: one row, left to right; a scale of +0 is not negative.
    let (w, h, px) = decode_image(Path::new("x.pfm"), &[b"PF\n3 1\n0\n".as_slice(), &be(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])].concat(), false).unwrap();
    assert_eq!((w, h, px), (3, 1, vec![Rgb::new(1.0, 2.0, 3.0), Rgb::new(4.0, 5.0, 6.0), Rgb::new(7.0, 8.0, 9.0)]));
    // 3 × 2 "PF": rows swapped, columns kept.
    let values: Vec<f32> = (1..=18).map(|v| v as f32).collect();
    let (_, _, px) = decode_image(Path::new("x.pfm"), &[b"PF\n3 2\n-1\n".as_slice(), &le(&values)].concat(), false).unwrap();
    let rgb = |k: usize| Rgb::new(values[3 * k], values[3 * k + 1], values[3 * k + 2]);
    assert_eq!(px, vec![rgb(3), rgb(4), rgb(5), rgb(0), rgb(1), rgb(2)]);
    // Bytes in the wrong order are other numbers: 1.0f32 is 00 00 80 3F little endian.
    let (_, _, px) = decode_image(Path::new("x.pfm"), b"Pf\n1 1\n-1\n\x00\x00\x80\x3F", false).unwrap();
    assert_eq!(px, vec![Rgb::ONE]);
    let (_, _, px) = decode_image(Path::new("x.pfm"), b"Pf\n1 1\n1\n\x3F\x80\x00\x00", false).unwrap();
    assert_eq!(px, vec![Rgb::ONE]);
    // The extension is not case-sensitive.
    assert_eq!(decode_image(Path::new("X.PFM"), b"Pf\n1 1\n1\n\x3F\x80\x00\x00", false).unwrap().2, vec![Rgb::ONE]);
    assert_eq!(decode_image(Path::new("x.pfm"), b"PF\n1 1\n-1\n\0\0\0\0\0\0\0\0\0\0\0", false).unwrap_err().to_string(), "x.pfm: truncated: expected 12 bytes of pixels");
}

/// A 2 × 1 8-bit RGB PNG written from the PNG specification (ISO/IEC 15948): signature, IHDR
/// (width 2, height 1, depth 8, colour type 2, no interlace), one IDAT holding a zlib stream
/// with a single stored deflate block of the filtered row (filter byte 0, then
/// 255 0 51  188 1 128), IEND. CRCs and the Adler-32 were computed with Python's `zlib`.
const PNG_2X1: &[u8] = &[
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, // signature
    0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x08, 0x02, 0x00, 0x00, 0x00, 0x7b, 0x40, 0xe8, 0xdd, // IHDR
    0x00, 0x00, 0x00, 0x12, 0x49, 0x44, 0x41, 0x54, 0x78, 0x01, 0x01, 0x07, 0x00, 0xf8, 0xff, // IDAT: zlib header, stored block of 7 bytes
    0x00, 0xff, 0x00, 0x33, 0xbc, 0x01, 0x80, // filter 0, two pixels
    0x09, 0x83, 0x02, 0x70, 0x5c, 0xf9, 0x70, 0xae, // Adler-32, CRC
    0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82, // IEND
];

#[test]
fn png_reader_decodes_a_hand_written_file() {
    let (w, h, px) = decode_image(Path::new("x.png"), PNG_2X1, false).unwrap();
    assert_eq!((w, h), (2, 1));
    close(&px, &[[1.0, 0.0, 0.2], [188.0 / 255.0, 1.0 / 255.0, 128.0 / 255.0]]);
    // Colour maps decode sRGB.
    let (_, _, px) = decode_image(Path::new("x.png"), PNG_2X1, true).unwrap();
    close(&px, &[[1.0, 0.0, srgb_decode(0.2)], [srgb_decode(188.0 / 255.0), 1.0 / 255.0 / 12.92, srgb_decode(128.0 / 255.0)]]);
    // Through the file system too.
    let path = temp("hand.png");
    std::fs::write(&path, PNG_2X1).unwrap();
    let (w, h, px) = raylab_loader::image_io::read_image(&path, false).unwrap();
    assert_eq!((w, h, px[0]), (2, 1, Rgb::new(1.0, 0.0, 0.2)));
    // The extension picks the decoder: the PNG's bytes are no PPM, and a PPM's no PNG.
    assert_eq!(decode_image(Path::new("x.ppm"), PNG_2X1, false).unwrap_err().to_string(), "x.ppm: not a binary PPM file (magic `\u{fffd}PNG`, expected P6)");
    assert!(decode_image(Path::new("x.png"), b"P6 1 1 255\n\0\0\0", false).unwrap_err().to_string().starts_with("x.png: cannot decode image: "));
}

/// The header of a scan-line OpenEXR file of float R, G, B (12 bytes a pixel) over the data
/// window (0, 0)–(`max_x`, `max_y`), with the given compression, and no pixels after it.
fn exr_header_only(compression: u8, max_x: i32, max_y: i32) -> Vec<u8> {
    let mut f = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
    let mut chlist = Vec::new();
    for name in ["B", "G", "R"] {
        chlist.extend(name.as_bytes());
        chlist.push(0);
        chlist.extend(2i32.to_le_bytes()); // FLOAT
        chlist.extend([0, 0, 0, 0]);
        chlist.extend(i32s(&[1, 1]));
    }
    chlist.push(0);
    attribute(&mut f, "channels", "chlist", &chlist);
    attribute(&mut f, "compression", "compression", &[compression]);
    attribute(&mut f, "dataWindow", "box2i", &i32s(&[0, 0, max_x, max_y]));
    attribute(&mut f, "displayWindow", "box2i", &i32s(&[0, 0, max_x, max_y]));
    attribute(&mut f, "lineOrder", "lineOrder", &[0]);
    attribute(&mut f, "pixelAspectRatio", "float", &1.0f32.to_le_bytes());
    attribute(&mut f, "screenWindowCenter", "v2f", &le(&[0.0, 0.0]));
    attribute(&mut f, "screenWindowWidth", "float", &1.0f32.to_le_bytes());
    // A comment padding the file to a multiple of 3 bytes, so that 8192·len/12 is whole.
    let pad = (0..3).find(|k| (f.len() + 20 + (1 + k) + 1).is_multiple_of(3)).unwrap();
    attribute(&mut f, "comments", "string", &vec![b'x'; 1 + pad]);
    f.push(0);
    f
}

/// The bounds before any pixel is allocated: a layer of w·h·12 bytes of RGB, and a block of
/// (scan lines per block)·w·(bytes per pixel), each at most 8192 (2¹³) times the file's size
/// (a multiple of 3 here, so that both bounds can be met exactly). A ZIP file (16 scan lines
/// a block) one line high and 100 000 pixels wide announces a layer of 1.2 MB, within 8192 ×
/// its few hundred bytes (~2.7 MB), but blocks of 16 · 100 000 · 12 = 19.2 MB, beyond it.
/// Without compression (one line a block) the same header passes both bounds and fails
/// later, for want of pixels.
#[test]
fn exr_bounds_are_the_layer_and_the_block_against_8192_times_the_file() {
    let zip = exr_header_only(3, 99_999, 0);
    let len = zip.len();
    assert!(len.is_multiple_of(3) && 1_200_000 <= len * 8192 && len * 8192 < 19_200_000, "{len}");
    let e = |name: &str, bytes: &[u8]| decode_image(Path::new(name), bytes, false).unwrap_err().to_string();
    assert_eq!(e("z.exr", &zip), format!("z.exr: its blocks of 16 scan lines cannot be stored in a file of {len} bytes"));
    assert!(e("r.exr", &exr_header_only(0, 99_999, 0)).starts_with("r.exr: cannot decode OpenEXR: "));
    // The block bound met exactly: 16 · w · 12 = 8192·len at w = 128·len/3 passes it, one
    // pixel wider does not.
    let w = (128 * len / 3) as i32;
    assert!(e("b.exr", &exr_header_only(3, w - 1, 0)).starts_with("b.exr: cannot decode OpenEXR: "));
    assert_eq!(e("b.exr", &exr_header_only(3, w, 0)), format!("b.exr: its blocks of 16 scan lines cannot be stored in a file of {len} bytes"));
    // The layer bound met exactly: 1 × h with h·12 = 8192·len passes it (ZIP's blocks of 16
    // lines of a 1-pixel-wide layer are 192 bytes, far within), one line more does not.
    let h = (8192 * len / 12) as i32;
    assert_eq!(exr_header_only(3, 0, h).len(), len);
    assert!(e("o.exr", &exr_header_only(3, 0, h - 1)).starts_with("o.exr: cannot decode OpenEXR: "));
    assert_eq!(e("t.exr", &exr_header_only(3, 0, h)), format!("t.exr: its 1×{} layer cannot be stored in a file of {len} bytes", h + 1));
}

/// `decode_image`'s "image has no pixels" cannot fire: every decoder refuses an empty image
/// first, each with its own message (so `w == 0 || h == 0` → `&&` is equivalent).
#[test]
fn no_decoder_returns_an_empty_image() {
    let e = |name: &str, bytes: &[u8]| decode_image(Path::new(name), bytes, false).unwrap_err().to_string();
    // PNG_2X1 with width 0 in IHDR (and its CRC, from Python's `zlib`, 0x7fb538e0).
    let mut png = PNG_2X1.to_vec();
    png[16..20].copy_from_slice(&[0, 0, 0, 0]);
    png[29..33].copy_from_slice(&[0x7f, 0xb5, 0x38, 0xe0]);
    let m = e("x.png", &png);
    assert!(m.starts_with("x.png: cannot decode image: ") && m.contains("Invalid image dimensions"), "{m}");
    // OpenEXR with a data window of width 0 ((0, 0)–(−1, 0)): header only, and with an
    // offset table and its one (empty) line.
    assert!(e("x.exr", &exr_header_only(0, -1, 0)).starts_with("x.exr: cannot decode OpenEXR: "));
    let mut exr = exr_header_only(0, -1, 0);
    let first = exr.len() + 8;
    exr.extend((first as u64).to_le_bytes());
    exr.extend(i32s(&[0, 0]));
    assert!(e("x.exr", &exr).starts_with("x.exr: cannot decode OpenEXR: "), "{}", e("x.exr", &exr));
    assert_eq!(e("x.ppm", b"P6 0 1 255\n"), "x.ppm: header: size 0x1 out of range (1..=65536)");
    assert_eq!(e("x.pfm", b"PF 1 0 -1\n"), "x.pfm: header: size 1x0 out of range (1..=65536)");
}
