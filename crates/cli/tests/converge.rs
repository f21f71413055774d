//! `raylab converge` end to end on a tiny scene: the files it writes, the convergence it
//! measures, and its errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn raylab(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raylab")).args(args).current_dir(dir).output().expect("raylab runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A folder holding a Lambertian floor seen from below a sphere light (the light itself out
/// of view, so every pixel is a smooth integral): `floor.toml`, 16×12 pixels, random sampler.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raylab-converge-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(
        d.join("floor.toml"),
        r#"
[camera]
from = [0, 1, 0]
at = [0, 0, 0]
up = [0, 0, 1]
vfov = 90
width = 16
height = 12

[render]
integrator = "direct"
sampler = "random"

[[materials]]
name = "floor"
type = "diffuse"
albedo = 0.5

[[shapes]]
type = "quad"
vertices = [[-50, 0, -50], [-50, 0, 50], [50, 0, 50], [50, 0, -50]]
material = "floor"

[[lights]]
type = "sphere"
center = [0, 2, 0]
radius = 0.5
radiance = 4
"#,
    )
    .unwrap();
    d
}

fn fails_with(args: &[&str], dir: &Path, message: &str) {
    let o = raylab(args, dir);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert_eq!(err.trim_end(), format!("raylab: error: {message}"), "{args:?}");
}

#[test]
fn measures_every_strategy_against_a_rendered_reference() {
    let dir = scratch("study");
    let o = raylab(&["converge", "floor.toml", "--spp", "1,4,16,64", "--reference-spp", "1024", "-o", "out"], &dir);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout.starts_with("no --reference given: rendered one with mis at 1024 spp (out"), "{stdout}");
    let out = dir.join("out");
    let csv = std::fs::read_to_string(out.join("convergence.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("strategy,spp,seconds,mse,rmse,rel_mse"));
    let rows: Vec<(String, u32, f64)> = lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 6, "{l}");
            (f[0].to_string(), f[1].parse().unwrap(), f[3].parse().unwrap())
        })
        .collect();
    let strategies = ["uniform", "solid-angle", "bsdf", "mis"];
    assert_eq!(rows.len(), strategies.len() * 4);
    for s in strategies {
        let mse = |spp: u32| rows.iter().find(|r| r.0 == s && r.1 == spp).unwrap_or_else(|| panic!("{s} at {spp} spp")).2;
        assert!(mse(64) < mse(1), "{s}: MSE {} at 1 spp, {} at 64", mse(1), mse(64));
        assert!(out.join(format!("{s}_64.exr")).exists(), "{s}_64.exr");
        assert!(!out.join(format!("{s}_16.exr")).exists(), "only the highest spp is kept");
    }
    // Independent samples: MSE ∝ 1/spp, a slope of −1 up to the noise of 192 pixels.
    let slopes = stdout.split_once("slope of").unwrap_or_else(|| panic!("no slopes: {stdout}")).1;
    let mis = slopes.lines().find_map(|l| l.trim().strip_prefix("mis ")).unwrap_or_else(|| panic!("no slope for mis: {stdout}"));
    let slope: f64 = mis.trim().parse().unwrap();
    assert!((-1.6..=-0.6).contains(&slope), "mis slope {slope}");
    assert!(out.join("reference.exr").exists());
    let page = std::fs::read_to_string(out.join("convergence.html")).unwrap();
    assert_eq!(page.matches("<svg").count(), 2);
}

#[test]
fn errors_name_the_option_at_fault() {
    let dir = scratch("errors");
    fails_with(&["converge", "floor.toml", "--strategies", "mis,grid", "-o", "out"], &dir, "--strategies: unknown light sampling `grid` (valid: uniform, solid-angle, cells, bsdf, mis)");
    fails_with(
        &["converge", "floor.toml", "--sampler", "jittered", "--spp", "1,2,4", "-o", "out"],
        &dir,
        "--spp: the jittered sampler needs a square number of samples (1, 4, 9, 16, ...), found 2",
    );
    let o = raylab(&["render", "floor.toml", "--width", "8", "--height", "8", "--spp", "1", "-q", "-o", "small.exr"], &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    fails_with(&["converge", "floor.toml", "--reference", "small.exr", "-o", "out"], &dir, "the reference small.exr is 8×8 but the renders are 16×12 (set --width and --height)");
}
