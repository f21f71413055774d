//! `raylab compare` on small PFM images with hand-computed errors: the metrics, exclusion of
//! bright pixels, the difference image, and exact error messages.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use raylab_core::Rgb;
use raylab_loader::image_io::{read_image, write_image, Tonemap};
use serde_json::Value;

fn raylab(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raylab")).args(args).current_dir(dir).output().expect("raylab runs")
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raylab-compare-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes a `w`×`h` PFM image into `dir`, every pixel `v` except those listed in `special`.
fn image(dir: &Path, name: &str, (w, h): (u32, u32), v: f32, special: &[(usize, f32)]) {
    let mut pixels = vec![Rgb::splat(v); (w * h) as usize];
    for &(i, s) in special {
        pixels[i] = Rgb::splat(s);
    }
    write_image(&dir.join(name), w, h, &pixels, Tonemap::Clamp, 0.0).unwrap();
}

fn json(args: &[&str], dir: &Path) -> Value {
    let o = raylab(args, dir);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Runs raylab expecting failure with exactly `message` (after `raylab: error: `) and no panic.
fn fails_with(args: &[&str], dir: &Path, message: &str) {
    let o = raylab(args, dir);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    assert_eq!(err.trim_end(), format!("raylab: error: {message}"), "{args:?}");
}

#[test]
fn metrics_match_hand_computed_values() {
    let dir = scratch("metrics");
    image(&dir, "a.pfm", (4, 3), 0.5, &[]);
    image(&dir, "b.pfm", (4, 3), 0.25, &[]);
    let j = json(&["compare", "a.pfm", "b.pfm", "--json"], &dir);
    assert_eq!(j["mse"], 0.0625, "{j}");
    assert_eq!(j["rmse"], 0.25, "{j}");
    assert_eq!(j["max_abs"], 0.25, "{j}");
    assert!((j["rel_mse"].as_f64().unwrap() - 0.0625 / (0.0625 + 1e-2)).abs() < 1e-12, "{j}");
    assert!((j["psnr_db"].as_f64().unwrap() - 10.0 * 16f64.log10()).abs() < 1e-9, "{j}");
    assert_eq!((j["pixels"].as_u64(), j["excluded"].as_u64()), (Some(12), Some(0)), "{j}");
    assert_eq!((j["width"].as_u64(), j["height"].as_u64()), (Some(4), Some(3)), "{j}");

    // The human table says the same.
    let o = raylab(&["compare", "a.pfm", "b.pfm"], &dir);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("MSE           6.250000e-2"), "{text}");
    assert!(text.contains("12 compared, 0 excluded"), "{text}");
}

#[test]
fn identical_images_have_zero_error_and_null_psnr() {
    let dir = scratch("identical");
    image(&dir, "a.pfm", (3, 2), 0.75, &[]);
    let j = json(&["compare", "a.pfm", "a.pfm", "--json"], &dir);
    assert_eq!((j["mse"].as_f64(), j["rmse"].as_f64(), j["rel_mse"].as_f64()), (Some(0.0), Some(0.0), Some(0.0)), "{j}");
    assert!(j["psnr_db"].is_null(), "{j}");
}

#[test]
fn exclude_bright_drops_pixels_bright_in_the_reference() {
    let dir = scratch("exclude");
    // Two lights in the reference, and a firefly in the render that stays counted.
    image(&dir, "a.pfm", (4, 4), 0.5, &[(5, 8.0)]);
    image(&dir, "b.pfm", (4, 4), 0.5, &[(0, 4.0), (15, 2.0)]);
    let j = json(&["compare", "a.pfm", "b.pfm", "--exclude-bright", "1.5", "--json"], &dir);
    assert_eq!((j["pixels"].as_u64(), j["excluded"].as_u64()), (Some(14), Some(2)), "{j}");
    assert_eq!(j["mse"], 7.5 * 7.5 / 14.0, "{j}");
    let j = json(&["compare", "a.pfm", "b.pfm", "--exclude-bright", "3", "--json"], &dir);
    assert_eq!((j["pixels"].as_u64(), j["excluded"].as_u64()), (Some(15), Some(1)), "{j}");
}

#[test]
fn diff_writes_a_false_colour_png_of_the_same_size() {
    let dir = scratch("diff");
    image(&dir, "a.pfm", (5, 3), 0.5, &[(7, 0.9)]);
    image(&dir, "b.pfm", (5, 3), 0.5, &[]);
    let j = json(&["compare", "a.pfm", "b.pfm", "--diff", "d.png", "--json"], &dir);
    let (w, h, pixels) = read_image(&dir.join("d.png"), true).unwrap();
    assert_eq!((w, h), (5, 3));
    // The one differing pixel stands out from the uniform rest.
    assert_ne!(pixels[7], pixels[0]);
    assert!(pixels.iter().enumerate().all(|(i, p)| i == 7 || *p == pixels[0]));
    assert!(j["diff_scale"].as_f64().is_some(), "{j}");
}

#[test]
fn bad_input_fails_with_exact_messages() {
    let dir = scratch("errors");
    image(&dir, "A.pfm", (64, 48), 0.5, &[]);
    image(&dir, "B.pfm", (32, 24), 0.5, &[]);
    // Written by hand, as write_image replaces NaN: a greyscale PFM, bottom row first.
    let mut nan = b"Pf\n2 2\n-1.0\n".to_vec();
    for v in [0.5, f32::NAN, 0.5, 0.5f32] {
        nan.extend(v.to_le_bytes());
    }
    std::fs::write(dir.join("nan.pfm"), nan).unwrap();
    fails_with(&["compare", "A.pfm", "B.pfm"], &dir, "A.pfm and B.pfm differ in size: 64×48 against 32×24");
    fails_with(&["compare", "A.pfm", "absent.pfm"], &dir, "absent.pfm: cannot read: No such file or directory (os error 2)");
    fails_with(&["compare", "nan.pfm", "B.pfm"], &dir, "nan.pfm: pixel (1, 1) is not a finite number");
    fails_with(&["compare", "A.pfm", "A.pfm", "--exclude-bright=-1"], &dir, "--exclude-bright: expected a finite number above 0, found -1");
    fails_with(&["compare", "A.pfm", "A.pfm", "--exclude-bright", "inf"], &dir, "--exclude-bright: expected a finite number above 0, found inf");
    fails_with(&["compare", "B.pfm", "B.pfm", "--exclude-bright", "0.25"], &dir, "B.pfm against B.pfm: all 768 pixels are excluded as brighter than 0.25 in the reference");
    fails_with(&["compare", "A.pfm", "A.pfm", "--diff", "d.bmp"], &dir, "d.bmp: unknown image format `.bmp` (valid: png, ppm, exr, pfm)");
}
