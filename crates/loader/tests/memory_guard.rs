//! The resource guard in the readers, alone in its test binary because it sets
//! `RAYLAB_MEMORY_LIMIT` for the whole process: an OpenEXR header announcing more pixels
//! than memory holds is refused before the pixel buffer is allocated.

use std::path::Path;

use raylab_core::Rgb;
use raylab_loader::image_io::{decode_image, encode_image, Tonemap};

#[test]
fn an_exr_larger_than_memory_is_refused_before_allocating() {
    let pixels = vec![Rgb::splat(0.5); 64 * 64];
    let bytes = encode_image(Path::new("x.exr"), 64, 64, &pixels, Tonemap::Clamp, 0.0).unwrap();
    // This test binary runs no other test: no other thread reads the environment.
    std::env::set_var("RAYLAB_MEMORY_LIMIT", "16K");
    let e = decode_image(Path::new("x.exr"), &bytes, false).unwrap_err();
    assert_eq!(e.to_string(), "x.exr: its 64×64 layer would need 48.0 KiB of memory, more than the 16.0 KiB this process may use (pass --allow-large to try anyway)");
    std::env::set_var("RAYLAB_MEMORY_LIMIT", "1M");
    assert_eq!(decode_image(Path::new("x.exr"), &bytes, false).unwrap().2, pixels);
}
