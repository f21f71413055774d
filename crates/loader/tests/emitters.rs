//! Emitters seen directly read exactly their radiance: the Cornell box's MTL light.

use std::path::PathBuf;

use raylab_core::Rgb;
use raylab_loader::{load_scene, Overrides};
use raylab_render::IntegratorKind;

#[test]
fn cornell_box_light_pixels_read_exactly_its_radiance() {
    if !raylab_testkit::shared_files(&["CornellBox-Original.obj", "CornellBox-Original.mtl"]) {
        return;
    }
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell_path.toml");
    // Looking up at the ceiling: only what the camera sees directly (max_depth 1).
    let overrides = Overrides { width: Some(48), height: Some(48), spp: Some(4), max_depth: Some(1), integrator: Some(IntegratorKind::Path), ..Default::default() };
    let mut scene = load_scene(&path, &overrides).unwrap();
    scene.camera = raylab_render::Camera::new(raylab_core::Vec3::new(0.0, 1.0, 0.0), raylab_core::Vec3::new(0.0, 2.0, 0.0), raylab_core::Vec3::Z, 40.0, 1.0, 0.0, None).unwrap();
    let img = raylab_render::render(&scene, &|_| {});
    // `Ke 17 12 4` in CornellBox-Original.mtl. Every pixel is k/4 of it (k of the 4 samples
    // hit the light), or black: nothing else emits and depth 1 reflects nothing.
    let ke = Rgb::new(17.0, 12.0, 4.0);
    let mut full = 0;
    for p in &img.pixels {
        let k = (p.x / ke.x * 4.0).round();
        assert!((*p - ke * (k / 4.0)).abs().max_element() < 1e-5, "pixel {p} is not a multiple of Ke/4");
        full += usize::from(k == 4.0);
    }
    assert!(full > 100, "only {full} pixels see the light fully");
}
