//! `raylab render --aovs`: one multi-layer EXR holding the beauty and every AOV, read back
//! with the exr crate and checked on a scene with closed-form answers; and the warnings and
//! errors around AOV output.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn raylab(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raylab")).args(args).current_dir(dir).output().expect("raylab runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raylab-aovs-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every channel of the EXR's first part: name -> values, row-major from the top.
fn channels(path: &Path) -> BTreeMap<String, Vec<f32>> {
    use exr::prelude::*;
    let image = read().no_deep_data().largest_resolution_level().all_channels().first_valid_layer().all_attributes().from_file(path).unwrap();
    image.layer_data.channel_data.list.iter().map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect())).collect()
}

/// A unit sphere of albedo (0.25, 0.5, 0.75) at the origin seen from z = 4, 15×15 pixels of 2° (vfov 30): the centre pixel looks along -z at the
/// sphere's pole (0, 0, 1), 3 units away; the corners see only the background.
const SPHERE: &str = "[camera]\nfrom = [0, 0, 4]\nat = [0, 0, 0]\nvfov = 30\nwidth = 15\nheight = 15\n\
[render]\nintegrator = \"albedo\"\nspp = 16\n\
[[materials]]\nname = \"m\"\ntype = \"diffuse\"\nalbedo = [0.25, 0.5, 0.75]\n\
[[shapes]]\ntype = \"sphere\"\nmaterial = \"m\"\ncenter = [0, 0, 0]\nradius = 1\n";

#[test]
fn every_aov_is_a_layer_of_one_exr() {
    let dir = scratch("layers");
    std::fs::write(dir.join("sphere.toml"), SPHERE).unwrap();
    let o = raylab(&["render", "sphere.toml", "--aovs", "albedo,normal,depth,variance", "-o", "out.exr", "--quiet"], &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    let c = channels(&dir.join("out.exr"));
    let names: Vec<&str> = c.keys().map(String::as_str).collect();
    assert_eq!(names, ["B", "G", "R", "albedo.B", "albedo.G", "albedo.R", "depth.Z", "normal.X", "normal.Y", "normal.Z", "variance.Y"]);
    let (centre, corner) = (7 * 15 + 7, 0);
    let at = |i: usize, names: [&str; 3]| names.map(|n| c[n][i]);
    // The beauty is the albedo integrator here, so both equal the material's albedo.
    assert_eq!(at(centre, ["R", "G", "B"]), [0.25, 0.5, 0.75]);
    assert_eq!(at(centre, ["albedo.R", "albedo.G", "albedo.B"]), [0.25, 0.5, 0.75]);
    // A sample θ ≤ 1.42° (the pixel's half-diagonal) off the axis passes the centre at
    // d = 4 sin θ ≤ 0.099 and hits where the normal is α + θ ≤ 7.1° off +z (sin α = d), at
    // distance 4 cos θ - √(1 - d²) ≤ 3.004: the mean normal is within 7.1° of +z, the depth in [3, 3.004].
    let n = at(centre, ["normal.X", "normal.Y", "normal.Z"]);
    assert!(n[0].abs() < 0.124 && n[1].abs() < 0.124 && (0.9923..=1.0).contains(&n[2]), "normal {n:?}");
    assert!((3.0..=3.004).contains(&c["depth.Z"][centre]), "depth {}", c["depth.Z"][centre]);
    // Every sample of a pixel inside the sphere or inside the background has the same albedo.
    assert_eq!((c["variance.Y"][centre], c["variance.Y"][corner]), (0.0, 0.0));
    // The corner sees nothing: 0 in the beauty and every AOV.
    assert_eq!(at(corner, ["R", "normal.X", "normal.Y"]), [0.0; 3]);
    assert_eq!(at(corner, ["normal.Z", "depth.Z", "albedo.R"]), [0.0; 3]);
    // The silhouette mixes sphere and background: some pixel there has a variance.
    assert!(c["variance.Y"].iter().any(|&v| v > 0.0));
}

#[test]
fn aov_output_errors_and_the_depth_warning() {
    let dir = scratch("errors");
    std::fs::write(dir.join("sphere.toml"), SPHERE).unwrap();
    let fails = |args: &[&str], message: &str| {
        let o = raylab(args, &dir);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert_eq!(stderr(&o).trim_end(), format!("raylab: error: {message}"), "{args:?}");
    };
    fails(&["render", "sphere.toml", "--aovs", "depth", "-o", "d.png"], "d.png: --aovs writes one multi-layer OpenEXR file: give -o FILE.exr");
    fails(&["render", "sphere.toml", "--aovs", "depth,depth", "-o", "d.exr"], "--aovs: `depth` is given twice");
    fails(&["render", "sphere.toml", "--aovs", "depth", "--tile", "0/2", "-o", "d.film"], "d.film: --aovs writes one multi-layer OpenEXR file: give -o FILE.exr");
    let o = raylab(&["render", "sphere.toml", "--aovs", "nromal", "-o", "d.exr"], &dir);
    assert!(stderr(&o).contains("invalid value 'nromal' for '--aovs <AOV,...>'") && stderr(&o).contains("[possible values: albedo, normal, depth, variance]"), "{}", stderr(&o));
    // Depth into an 8-bit PNG: said once, and the image is still written.
    let o = raylab(&["render", "sphere.toml", "--integrator", "depth", "-o", "d.png", "--quiet"], &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o).matches("depth is a distance in scene units").count(), 1, "{}", stderr(&o));
    assert!(stderr(&o).starts_with("warning: d.png: depth is a distance in scene units, and an 8-bit image clips it at 1"), "{}", stderr(&o));
    let o = raylab(&["render", "sphere.toml", "--integrator", "depth", "-o", "d.exr", "--quiet"], &dir);
    assert!(o.status.success() && !stderr(&o).contains("warning"), "{}", stderr(&o));
}
