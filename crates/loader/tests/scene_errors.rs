//! Malformed input gives an error naming the file, the line and the field — asserted by
//! its exact message, as pbrt's parser tests do.

use std::path::{Path, PathBuf};

use raylab_loader::{load_scene, load_scene_str, Overrides};
use raylab_loader::files::Resolver;

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// Loads `src` as `bad.toml` from the fixtures folder and returns the error message.
fn error_of(src: &str) -> String {
    let base = fixtures();
    match load_scene_str(src, Path::new("bad.toml"), &Resolver::Disk { base }, &Overrides::default()) {
        Ok(_) => panic!("scene loaded but should not:\n{src}"),
        Err(e) => e.to_string(),
    }
}

const CAMERA: &str = "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n";

#[test]
fn wrong_value_type_names_line_and_field() {
    assert_eq!(error_of("[camera]\nfrom = [0, 0, 5]\nat = \"origin\"\nvfov = 40\n"), "bad.toml:3: camera.at: expected an array of 3 numbers, found a string");
    assert_eq!(error_of("[camera]\nfrom = [0, 0]\nat = [0, 0, 0]\nvfov = 40\n"), "bad.toml:2: camera.from: expected an array of 3 numbers, found an array of 2 elements");
    assert_eq!(error_of("[camera]\nfrom = [0, \"x\", 5]\nat = [0, 0, 0]\nvfov = 40\n"), "bad.toml:2: camera.from: expected an array of 3 numbers, found a string at index 1");
}

#[test]
fn unknown_keys_and_types_list_the_valid_ones() {
    assert_eq!(
        error_of("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nfov = 40\n"),
        "bad.toml:4: camera.fov: unknown field (valid: from, at, up, vfov, width, height, aperture, focus_distance)"
    );
    assert_eq!(
        error_of(&format!("{CAMERA}[[shapes]]\ntype = \"cylinder\"\n")),
        "bad.toml:6: shapes[0].type: unknown type `cylinder` (valid: sphere, triangle, quad, mesh, curve, bezier_patch)"
    );
    assert_eq!(
        error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = 1\nvertices = [[0, 0, 0]]\n")),
        "bad.toml:8: shapes[0].vertices: not a field of `sphere` shapes (valid: type, material, transform, center, radius)"
    );
    assert_eq!(
        error_of(&format!("{CAMERA}[render]\naccel = \"octree\"\n")),
        format!("bad.toml:6: render.accel: unknown acceleration structure `octree` (valid: {})", raylab_accel::AccelKind::names())
    );
    assert_eq!(error_of("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n[lens]\n"), "bad.toml:5: lens: unknown field (valid: camera, render, background, textures, materials, shapes, lights)");
}

#[test]
fn out_of_range_values() {
    assert_eq!(error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = -1\n")), "bad.toml:7: shapes[0].radius: must be positive, found -1");
    assert_eq!(error_of("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 180\n"), "bad.toml:4: camera.vfov: must be in (0, 180) degrees, found 180");
    assert_eq!(error_of("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\nwidth = 0\n"), "bad.toml:5: camera.width: must be between 1 and 16384, found 0");
    assert_eq!(error_of(&format!("{CAMERA}[render]\nlight_cells = 17\n")), "bad.toml:6: render.light_cells: must be between 1 and 16, found 17");
    assert_eq!(error_of("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 5]\nvfov = 40\n"), "bad.toml:3: camera.at: must differ from camera.from");
    assert_eq!(error_of(&format!("{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [1, -1, 1]\n")), "bad.toml:8: lights[0].intensity: colour components must not be negative, found [1, -1, 1]");
    assert_eq!(error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = nan\n")), "bad.toml:7: shapes[0].radius: expected a finite number");
    assert_eq!(error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = 1\ntransform = [{{ scale = 0 }}]\n")), "bad.toml:8: shapes[0].transform[0].scale: scale must not be zero");
}

#[test]
fn references_to_undefined_names() {
    assert_eq!(error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = 1\nmaterial = \"gold\"\n")), "bad.toml:8: shapes[0].material: unknown material `gold` (defined: none)");
    assert_eq!(error_of(&format!("{CAMERA}[[materials]]\nname = \"m\"\ntype = \"diffuse\"\nalbedo = \"earth\"\n")), "bad.toml:8: materials[0].albedo: unknown texture `earth` (defined: none)");
    assert_eq!(error_of("vfov = 1\n"), "bad.toml:1: vfov: unknown field (valid: camera, render, background, textures, materials, shapes, lights)");
    assert_eq!(error_of("[render]\nspp = 4\n"), "bad.toml:1: camera: missing (required)");
}

#[test]
fn missing_files_name_every_path_tried() {
    let msg = error_of(&format!("{CAMERA}[[shapes]]\ntype = \"mesh\"\nfile = \"no_such_mesh.obj\"\n"));
    let direct = fixtures().join("no_such_mesh.obj");
    assert!(msg.starts_with(&format!("bad.toml:7: shapes[0].file: cannot find `no_such_mesh.obj` (looked in {}", direct.display())), "{msg}");
    let msg = error_of(&format!("{CAMERA}[[textures]]\nname = \"t\"\ntype = \"image\"\nfile = \"no_such_texture.png\"\n"));
    assert!(msg.starts_with("bad.toml:8: textures[0].file: cannot find `no_such_texture.png` (looked in "), "{msg}");
}

#[test]
fn malformed_obj_names_its_line() {
    let msg = error_of(&format!("{CAMERA}[[shapes]]\ntype = \"mesh\"\nfile = \"bad_index.obj\"\n"));
    assert_eq!(msg, format!("{}:6: face index 4 is out of range: the file has 3 vertex (`v`) entries", fixtures().join("bad_index.obj").display()));
    let msg = error_of(&format!("{CAMERA}[[shapes]]\ntype = \"mesh\"\nfile = \"bad_number.obj\"\n"));
    assert_eq!(msg, format!("{}:3: `v` expects numbers, found `1.0 zero 0.0`", fixtures().join("bad_number.obj").display()));
    let msg = error_of(&format!("{CAMERA}[[shapes]]\ntype = \"mesh\"\nfile = \"not_utf8.obj\"\n"));
    assert_eq!(msg, format!("{}:2: not valid UTF-8 (byte 0xff)", fixtures().join("not_utf8.obj").display()));
}

#[test]
fn non_utf8_and_syntax_errors_in_the_scene() {
    let path = fixtures().join("not_utf8.toml");
    let e = load_scene(&path, &Overrides::default()).unwrap_err().to_string();
    assert_eq!(e, format!("{}:3: not valid UTF-8 (byte 0xfe)", path.display()));
    let e = error_of("[camera\nfrom = 1\n");
    assert!(e.starts_with("bad.toml:1: TOML syntax error: "), "{e}");
    let missing = fixtures().join("nope.toml");
    let e = load_scene(&missing, &Overrides::default()).unwrap_err().to_string();
    assert!(e.starts_with(&format!("{}: cannot read: ", missing.display())), "{e}");
}

/// Whether the files `scene` names (`file = "…"`) that are not beside it are in the shared
/// scenes folder; each missing one is reported, and the scene is then skipped.
fn shared_files_present(scene: &Path) -> bool {
    let text = std::fs::read_to_string(scene).unwrap();
    let dir = scene.parent().unwrap();
    let names: Vec<&str> = text.lines().filter_map(|l| l.trim().strip_prefix("file = \"")?.strip_suffix('"')).filter(|name| !dir.join(name).is_file()).collect();
    raylab_testkit::shared_files(&names)
}

#[test]
fn example_scenes_and_default_scene_parse() {
    let scenes = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut n = 0;
    let files = std::fs::read_dir(&scenes).unwrap().chain(std::fs::read_dir(scenes.join("lab")).unwrap());
    for entry in files {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "toml") {
            n += 1;
            if !shared_files_present(&p) {
                continue;
            }
            let scene = load_scene(&p, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
            let g = &scene.geometry;
            assert!(!g.meshes.is_empty() || !g.spheres.is_empty() || !g.curves.is_empty(), "{}", p.display());
        }
    }
    assert!(n >= 15, "only {n} example scenes");
    let d = raylab_loader::default_scene(&Overrides::default()).unwrap();
    assert_eq!(d.geometry.triangle_count(), 4968 + 2);
    assert_eq!(d.geometry.spheres.len(), 2);
}

#[test]
fn environment_light_errors() {
    let env = "[[lights]]\ntype = \"environment\"\nfile = \"no_such_sky.exr\"\n";
    assert_eq!(error_of(&format!("{CAMERA}[background]\ncolor = 0.1\n{env}")), "bad.toml:8: lights[0].type: an environment light is the scene's background: remove `[background]`");
    assert!(error_of(&format!("{CAMERA}{env}")).starts_with("bad.toml:7: lights[0].file: cannot find `no_such_sky.exr` (looked in "));
    assert_eq!(error_of(&format!("{CAMERA}{env}scale = -2\n")), "bad.toml:8: lights[0].scale: colour components must not be negative, found [-2, -2, -2]");
    assert_eq!(error_of(&format!("{CAMERA}{env}radius = 2\n")), "bad.toml:8: lights[0].radius: not a field of `environment` lights (valid: type, file, scale)");
}

#[test]
fn conductor_errors() {
    let m = "[[materials]]\nname = \"m\"\ntype = \"conductor\"\n";
    assert_eq!(error_of(&format!("{CAMERA}{m}metal = \"tin\"\n")), "bad.toml:8: materials[0].metal: unknown metal `tin` (valid: gold, silver, copper, aluminium)");
    assert_eq!(error_of(&format!("{CAMERA}{m}metal = \"gold\"\neta = 1\n")), "bad.toml:9: materials[0].eta: give either `metal` or `eta` and `k`, not both");
    assert_eq!(error_of(&format!("{CAMERA}{m}k = 3\n")), "bad.toml:8: materials[0].k: `eta` and `k` go together: give both");
    assert_eq!(error_of(&format!("{CAMERA}{m}eta = [0.2, 0, 1]\nk = 3\n")), "bad.toml:8: materials[0].eta: components must be positive, found [0.2, 0, 1]");
    assert_eq!(error_of(&format!("{CAMERA}{m}roughness = 0\n")), "bad.toml:8: materials[0].roughness: must be between 0.001 and 10, found 0");
}

#[test]
fn mis_heuristic_names_the_valid_ones() {
    assert_eq!(error_of(&format!("{CAMERA}[render]\nmis_heuristic = \"cutoff\"\n")), "bad.toml:6: render.mis_heuristic: unknown MIS heuristic `cutoff` (valid: power, balance)");
}

#[test]
fn normal_and_bump_map_errors() {
    // Lines 5-8: a constant texture `h`; 9-11: a diffuse material; its extra fields from 12.
    let material = |extra: &str| error_of(&format!("{CAMERA}[[textures]]\nname = \"h\"\ntype = \"constant\"\ncolor = 0.5\n[[materials]]\nname = \"m\"\ntype = \"diffuse\"\n{extra}"));
    assert_eq!(material("normal_map = \"h\"\nbump_map = \"h\"\nbump_scale = 0.1\n"), "bad.toml:13: materials[0].bump_map: give either `normal_map` or `bump_map`, not both");
    assert_eq!(material("normal_space = \"tangent\"\n"), "bad.toml:12: materials[0].normal_space: needs `normal_map`");
    assert_eq!(material("bump_scale = 0.1\n"), "bad.toml:12: materials[0].bump_scale: needs `bump_map`");
    assert_eq!(material("normal_map = \"h\"\nnormal_space = \"world\"\n"), "bad.toml:13: materials[0].normal_space: unknown normal space `world` (valid: tangent, object)");
    assert_eq!(material("normal_map = \"nm\"\n"), "bad.toml:12: materials[0].normal_map: unknown texture `nm` (defined: h)");
    assert_eq!(material("normal_map = [0.5, 0.5, 1]\n"), "bad.toml:12: materials[0].normal_map: expected the name of a texture");
    assert_eq!(material("bump_map = \"h\"\n"), "bad.toml:9: materials[0].bump_scale: missing (required)");
    assert_eq!(material("bump_map = \"h\"\nbump_scale = 0\n"), "bad.toml:13: materials[0].bump_scale: must not be zero");
    assert_eq!(material("albedo = 1\nior = 1.5\n"), "bad.toml:13: materials[0].ior: not a field of `diffuse` materials (valid: name, type, normal_map, normal_space, bump_map, bump_scale, albedo)");
    // An image decoded from sRGB would bend every normal: it must be read as linear.
    let srgb = error_of(&format!(
        "{CAMERA}[[textures]]\nname = \"nm\"\ntype = \"image\"\nfile = \"textures/grass_normal_1024.jpg\"\n[[materials]]\nname = \"m\"\ntype = \"diffuse\"\nnormal_map = \"nm\"\n"
    ));
    assert_eq!(srgb, "bad.toml:12: materials[0].normal_map: texture `nm` is decoded from sRGB, but a normal map holds linear vectors: give it `srgb = false`");
}

/// glTF's metallic-roughness material in TOML: the texture holds data (read linear), the
/// factors are fractions.
#[test]
fn metallic_roughness_materials_load_and_check_their_fields() {
    let textures = "[[textures]]\nname = \"srgb\"\ntype = \"image\"\nfile = \"textures/grass_normal_1024.jpg\"\n\
                    [[textures]]\nname = \"orm\"\ntype = \"image\"\nfile = \"textures/grass_normal_1024.jpg\"\nsrgb = false\n";
    let material = |fields: &str| format!("{CAMERA}{textures}[[materials]]\nname = \"m\"\ntype = \"metallic-roughness\"\n{fields}");
    assert_eq!(error_of(&material("metallic_roughness = \"srgb\"\n")), "bad.toml:17: materials[0].metallic_roughness: texture `srgb` is decoded from sRGB, but `metallic_roughness` holds metalness and roughness: give it `srgb = false`");
    assert_eq!(error_of(&material("metallic_roughness = [1, 1, 1]\n")), "bad.toml:17: materials[0].metallic_roughness: must name a texture");
    assert_eq!(error_of(&material("roughness = 1.5\n")), "bad.toml:17: materials[0].roughness: must be between 0 and 1, found 1.5");
    assert_eq!(
        error_of(&material("ior = 1.5\n")),
        "bad.toml:17: materials[0].ior: not a field of `metallic-roughness` materials (valid: name, type, normal_map, normal_space, bump_map, bump_scale, base_color, metallic, roughness, metallic_roughness)"
    );
    let src = material("base_color = [0.9, 0.6, 0.2]\nmetallic = 0.25\nroughness = 0.5\nmetallic_roughness = \"orm\"\n");
    let scene = load_scene_str(&src, Path::new("ok.toml"), &Resolver::Disk { base: fixtures() }, &Overrides::default()).unwrap();
    use raylab_render::material::TexColor;
    use raylab_render::{Material, TextureId};
    assert_eq!(scene.materials[1], Material::MetallicRoughness { base_color: TexColor::Constant(raylab_core::Rgb::new(0.9, 0.6, 0.2)), metallic: 0.25, roughness: 0.5, metallic_roughness: Some(TextureId(1)) });
}

#[test]
fn normal_and_bump_maps_load() {
    let src = format!(
        "{CAMERA}[[textures]]\nname = \"nm\"\ntype = \"image\"\nfile = \"textures/grass_normal_1024.jpg\"\nsrgb = false\n\
         [[textures]]\nname = \"h\"\ntype = \"checker\"\n\
         [[materials]]\nname = \"mapped\"\ntype = \"phong\"\nnormal_map = \"nm\"\nnormal_space = \"object\"\n\
         [[materials]]\nname = \"bumpy\"\ntype = \"mirror\"\nbump_map = \"h\"\nbump_scale = -0.5\n\
         [[shapes]]\ntype = \"quad\"\nvertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\nmaterial = \"mapped\"\n"
    );
    let scene = load_scene_str(&src, Path::new("ok.toml"), &Resolver::Disk { base: fixtures() }, &Overrides::default()).unwrap();
    use raylab_render::shading::{NormalSpace, ShadingPerturbation};
    use raylab_render::TextureId;
    assert_eq!(scene.material_perturbations, vec![None, Some(ShadingPerturbation::NormalMap { texture: TextureId(0), space: NormalSpace::Object }), Some(ShadingPerturbation::Bump { texture: TextureId(1), scale: -0.5 })]);
}

/// A non-square count with the jittered sampler is rounded up to the next square (said once
/// on stderr), not blamed on the scene file.
#[test]
fn non_square_jittered_spp_rounds_up() {
    let scene = load_scene_str(&format!("{CAMERA}[render]\nspp = 10\n"), Path::new("ok.toml"), &Resolver::Disk { base: fixtures() }, &Overrides::default()).unwrap();
    assert_eq!(scene.settings.spp, 16);
    let scene = load_scene_str(&format!("{CAMERA}[render]\nspp = 10\n"), Path::new("ok.toml"), &Resolver::Disk { base: fixtures() }, &Overrides { spp: Some(5), ..Default::default() }).unwrap();
    assert_eq!(scene.settings.spp, 9);
    let sobol = load_scene_str(&format!("{CAMERA}[render]\nspp = 10\nsampler = \"sobol\"\n"), Path::new("ok.toml"), &Resolver::Disk { base: fixtures() }, &Overrides::default()).unwrap();
    assert_eq!(sobol.settings.spp, 10);
}

