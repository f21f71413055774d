//! Tone maps and the sRGB curve at known points: values from the published curves written
//! out here (Reinhard et al. 2002; Narkowicz 2016's fit of ACES; IEC 61966-2-1 for sRGB),
//! and the 8-bit codes they give in a written PPM, byte for byte.

use raylab_core::color::{linear_to_srgb, linear_to_srgb8, srgb_to_linear};
use raylab_core::Rgb;
use raylab_loader::image_io::{write_image, Tonemap};

/// Narkowicz 2016, "ACES Filmic Tone Mapping Curve": x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14).
fn aces(x: f64) -> f64 {
    (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

#[test]
fn reinhard_known_values() {
    // c / (1 + c): 1 → 1/2, 3 → 3/4, 0.25 → 1/5; exposure +1 doubles the input first.
    for (v, exposure, expected) in [(1.0f32, 0.0f32, 0.5f32), (3.0, 0.0, 0.75), (0.25, 0.0, 0.2), (0.5, 1.0, 0.5), (4.0, -1.0, 2.0 / 3.0)] {
        let got = Tonemap::Reinhard.apply(v, exposure);
        assert!((got - expected).abs() < 1e-6, "Reinhard({v}, exposure {exposure}) = {got}, expected {expected}");
    }
}

#[test]
fn aces_known_values() {
    // Hand values: ACES(1) = 2.54/3.16, ACES(0.18) = 0.0867/0.3249, saturation from
    // x = (0.56 + √0.3584)/0.16 ≈ 7.24 on.
    assert!((Tonemap::Aces.apply(1.0, 0.0) as f64 - 2.54 / 3.16).abs() < 1e-6);
    assert!((Tonemap::Aces.apply(0.18, 0.0) as f64 - 0.266_90).abs() < 1e-4);
    assert_eq!(Tonemap::Aces.apply(7.3, 0.0), 1.0);
    assert!(Tonemap::Aces.apply(7.2, 0.0) < 1.0);
    for x in [0.01f32, 0.05, 0.3, 0.7, 2.0, 5.0] {
        assert!((Tonemap::Aces.apply(x, 0.0) as f64 - aces(x as f64)).abs() < 1e-6, "ACES({x})");
    }
    // Exposure −2 scales by 1/4 before the curve.
    assert!((Tonemap::Aces.apply(4.0, -2.0) as f64 - 2.54 / 3.16).abs() < 1e-6);
}

#[test]
fn clamp_is_the_identity_below_one() {
    for v in [0.0f32, 0.2, 0.999] {
        assert_eq!(Tonemap::Clamp.apply(v, 0.0), v);
    }
    assert_eq!(Tonemap::Clamp.apply(7.0, 0.0), 1.0);
    assert_eq!(Tonemap::Clamp.apply(-1.0, 0.0), 0.0);
}

#[test]
fn srgb_curve_known_values() {
    // IEC 61966-2-1: linear 0.5 encodes to 0.735 4 (code 188), 18 % grey to 0.461 4 (code
    // 118); the linear segment meets the power one at 0.003 130 8 → 0.040 45.
    assert!((linear_to_srgb(0.5) - 0.735_36).abs() < 1e-4);
    assert!((linear_to_srgb(0.18) - 0.461_36).abs() < 1e-4);
    assert_eq!((linear_to_srgb8(0.5), linear_to_srgb8(0.18), linear_to_srgb8(1.0), linear_to_srgb8(0.0)), (188, 118, 255, 0));
    assert!((linear_to_srgb(0.003_130_8) - 0.040_45).abs() < 1e-5);
    assert!((linear_to_srgb(0.001) - 0.012_92).abs() < 1e-7);
    assert!((srgb_to_linear(0.5) - 0.214_04).abs() < 1e-5);
    assert!((srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-7);
}

#[test]
fn ppm_bytes_are_tone_mapped_then_srgb_encoded() {
    // Reinhard(1) = 0.5 → sRGB 0.7354 → 188; Reinhard(3) = 0.75 → 0.8808 → 225;
    // Reinhard(0) = 0 → 0; ACES(1) = 0.8038 → 0.9082 → 232.
    let dir = std::env::temp_dir().join(format!("raylab-tonemap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("t.ppm");
    write_image(&path, 2, 1, &[Rgb::new(1.0, 3.0, 0.0), Rgb::new(0.25, 1.0, 0.0)], Tonemap::Reinhard, 0.0).unwrap();
    // Reinhard(0.25) = 0.2 → sRGB 0.4845 → 124.
    assert_eq!(std::fs::read(&path).unwrap(), b"P6\n2 1\n255\n\xbc\xe1\x00\x7c\xbc\x00");
    write_image(&path, 1, 1, &[Rgb::new(1.0, 1.0, 1.0)], Tonemap::Aces, 0.0).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"P6\n1 1\n255\n\xe8\xe8\xe8");
    std::fs::remove_dir_all(&dir).unwrap();
}
