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
