//! The resource guard in the readers, alone in its test binary because it sets
//! `RAYLAB_MEMORY_LIMIT` for the whole process (one test, so that no other thread reads the
//! environment): an OpenEXR header, a PLY header or a glTF accessor announcing more than
//! memory holds is refused before anything is allocated for it.

use std::path::Path;

use raylab_core::{Rgb, Transform, Vec3};
use raylab_loader::gltf::parse_gltf;
use raylab_loader::image_io::{decode_image, encode_image, Tonemap};
use raylab_loader::ply::read_ply;

/// A glTF file with one triangle primitive whose POSITION accessor (3 floats) claims `count`
/// values: sparse without a view (that many zeros, the first replaced), or read from a view.
fn gltf_with_count(count: u64, sparse: bool) -> String {
    let mut bin = 0u32.to_le_bytes().to_vec();
    [0.0f32, 1.0, 2.0].iter().for_each(|x| bin.extend(x.to_le_bytes()));
    let accessor = if sparse {
        format!(r#"{{"componentType":5126,"count":{count},"type":"VEC3","min":[0,0,0],"max":[0,1,2],"sparse":{{"count":1,"indices":{{"bufferView":0,"componentType":5125}},"values":{{"bufferView":1}}}}}}"#)
    } else {
        format!(r#"{{"bufferView":1,"componentType":5126,"count":{count},"type":"VEC3","min":[0,0,0],"max":[0,1,2]}}"#)
    };
    let uri = format!("data:application/octet-stream;base64,{}", base64_encode(&bin));
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"accessors":[{accessor}],"bufferViews":[{{"buffer":0,"byteLength":4}},{{"buffer":0,"byteOffset":4,"byteLength":12}}],"buffers":[{{"byteLength":16,"uri":"{uri}"}}]}}"#
    )
}

fn base64_encode(bytes: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    bytes
        .chunks(3)
        .flat_map(|c| {
            let n = c.iter().enumerate().fold(0u32, |n, (i, &b)| n | (b as u32) << (16 - 8 * i));
            (0..4).map(move |k| if k <= c.len() { A[(n >> (18 - 6 * k)) as usize & 63] as char } else { '=' })
        })
        .collect()
}

#[test]
fn sizes_larger_than_memory_are_refused_before_allocating() {
    let pixels = vec![Rgb::splat(0.5); 64 * 64];
    let bytes = encode_image(Path::new("x.exr"), 64, 64, &pixels, Tonemap::Clamp, 0.0).unwrap();
    // This test binary runs no other test: no other thread reads the environment.
    std::env::set_var("RAYLAB_MEMORY_LIMIT", "16K");
    let e = decode_image(Path::new("x.exr"), &bytes, false).unwrap_err();
    assert_eq!(e.to_string(), "x.exr: its 64×64 layer would need 48.0 KiB of memory, more than the 16.0 KiB this process may use (pass --allow-large to try anyway)");
    std::env::set_var("RAYLAB_MEMORY_LIMIT", "1M");
    assert_eq!(decode_image(Path::new("x.exr"), &bytes, false).unwrap().2, pixels);

    // PLY: 10000 vertices of 3 bytes each fit in the file's 30000 bytes, but would need
    // 10000 × 32 + 1 × 12 bytes once read.
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 10000\nproperty uchar x\nproperty uchar y\nproperty uchar z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
    ply.extend((0..30000).map(|i| (i % 7) as u8));
    ply.push(3);
    [0u32, 1, 2].iter().for_each(|i| ply.extend(i.to_le_bytes()));
    std::env::set_var("RAYLAB_MEMORY_LIMIT", "64K");
    assert_eq!(read_ply(Path::new("x.ply"), &ply, &Transform::IDENTITY).unwrap_err().to_string(), "x.ply: its 10000 vertices and 1 faces would need 312.5 KiB of memory, more than the 64.0 KiB this process may use (pass --allow-large to try anyway)");
    std::env::set_var("RAYLAB_MEMORY_LIMIT", "1M");
    assert_eq!(read_ply(Path::new("x.ply"), &ply, &Transform::IDENTITY).unwrap().positions.len(), 10000);
    // An ASCII header claiming 10^12 vertices is refused by the file's size already.
    let ascii = "ply\nformat ascii 1.0\nelement vertex 1000000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(read_ply(Path::new("a.ply"), ascii.as_bytes(), &Transform::IDENTITY).unwrap_err().to_string(), "a.ply: element `vertex` claims 1000000000000 entries, more than the file's 26 bytes can hold");

    // glTF: a sparse accessor without a view is `count` zeros, however few bytes the file has.
    let dir = std::env::temp_dir().join(format!("raylab-memory-guard-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("x.gltf");
    std::fs::write(&file, gltf_with_count(1_000_000_000_000, true)).unwrap();
    assert_eq!(parse_gltf(&file).unwrap_err().to_string(), format!("{}: meshes[0].primitives[0]: accessors[0] (1000000000000 values) would need 11175.9 GiB of memory, more than the 1.0 MiB this process may use (pass --allow-large to try anyway)", file.display()));
    std::fs::write(&file, gltf_with_count(3, true)).unwrap();
    assert_eq!(parse_gltf(&file).unwrap().geometry.meshes[0].positions, [Vec3::new(0.0, 1.0, 2.0), Vec3::ZERO, Vec3::ZERO]);
    // Read from a view, the count must fit the view (12 bytes: one value).
    std::fs::write(&file, gltf_with_count(2, false)).unwrap();
    assert_eq!(parse_gltf(&file).unwrap_err().to_string(), format!("{}: meshes[0].primitives[0]: accessors[0]: 2 values run past bufferViews[1] (12 bytes)", file.display()));
    std::fs::remove_dir_all(&dir).unwrap();
}
