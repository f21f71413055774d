//! Every front end (TOML, bare OBJ/PLY, pbrt-v4) reads the same scene to the same image,
//! from files written by an independent tool: `tests/data/bunny_*.ply` were exported from
//! `assets/bunny_4968.obj` by trimesh 4.x (Python), the pbrt-v4 scenes written by hand.

use std::path::{Path, PathBuf};

use raylab_core::{Rgb, Vec3};
use raylab_loader::{load_scene_or_mesh, load_scene_str, Overrides};
use raylab_loader::files::Resolver;
use raylab_render::material::TexColor;
use raylab_render::{IntegratorKind, Material, SamplerKind, Scene};

fn data() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

fn pixels(scene: &Scene) -> Vec<Rgb> {
    raylab_render::render(scene, &|_| {}).pixels
}

/// Mean squared error over pixels and channels.
fn mse(a: &[Rgb], b: &[Rgb]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (*x - *y).length_squared() / 3.0).sum::<f32>() / a.len() as f32
}

fn mean(a: &[Rgb]) -> f32 {
    a.iter().map(|p| (p.x + p.y + p.z) / 3.0).sum::<f32>() / a.len() as f32
}

/// `tests/data/bunny.toml` with its mesh file replaced.
fn toml_with_mesh(file: &str) -> Scene {
    let src = std::fs::read_to_string(data().join("bunny.toml")).unwrap().replace("bunny_binary.ply", file);
    load_scene_str(&src, &data().join("bunny.toml"), &Resolver::Disk { base: data() }, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn toml_obj_ply_and_pbrt_render_the_same_image() {
    // The reference: the OBJ trimesh read, found on the shared scene path.
    let reference = toml_with_mesh("bunny_4968.obj");
    assert_eq!(reference.geometry.triangle_count(), 4968 + 2);
    let reference_px = pixels(&reference);
    // Not a black image: the comparison below would pass trivially.
    assert!(mean(&reference_px) > 0.05, "mean {}", mean(&reference_px));
    let pbrt = load_scene_or_mesh(&data().join("bunny.pbrt"), &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
    for (name, scene) in [("TOML + binary PLY", toml_with_mesh("bunny_binary.ply")), ("TOML + gzipped ASCII PLY", toml_with_mesh("bunny_ascii.ply.gz")), ("pbrt-v4", pbrt)] {
        assert_eq!(scene.geometry.triangle_count(), reference.geometry.triangle_count(), "{name}");
        assert_eq!((scene.settings.width, scene.settings.height, scene.settings.spp, scene.settings.max_depth), (64, 48, 4, 2), "{name}");
        assert_eq!((scene.settings.sampler, scene.settings.integrator), (SamplerKind::Random, IntegratorKind::Path), "{name}");
        // Same camera rays and samples, so only the vertex normals (trimesh recomputes
        // them, within 1e-3 of the OBJ's) make pixels differ.
        let e = mse(&reference_px, &pixels(&scene));
        assert!(e < 1e-4, "{name}: MSE {e} against the OBJ");
    }
}

#[test]
fn bare_obj_and_ply_are_framed_alike() {
    let obj = load_scene_or_mesh(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/bunny_4968.obj"), &Overrides { width: Some(48), height: Some(36), ..Default::default() }).unwrap();
    let ply = load_scene_or_mesh(&data().join("bunny_binary.ply"), &Overrides { width: Some(48), height: Some(36), ..Default::default() }).unwrap();
    assert_eq!(obj.geometry.triangle_count(), 4968);
    assert_eq!(ply.geometry.triangle_count(), 4968);
    assert_eq!(obj.camera.from, ply.camera.from);
    let (a, b) = (pixels(&obj), pixels(&ply));
    // The bunny covers about a fifth of the frame, on black.
    assert!(mean(&a) > 0.004, "mean {}", mean(&a));
    assert!(mse(&a, &b) < 1e-4, "MSE {}", mse(&a, &b));
}

#[test]
fn a_pbrt_scene_using_every_directive_of_the_subset() {
    let s = load_scene_or_mesh(&data().join("every_directive.pbrt"), &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
    // Film, Sampler and Integrator: zsobol -> sobol, maxdepth 3 bounces = 4 segments.
    assert_eq!((s.settings.width, s.settings.height, s.settings.spp), (48, 64, 8));
    assert_eq!((s.settings.sampler, s.settings.integrator, s.settings.max_depth), (SamplerKind::Sobol, IntegratorKind::Path, 4));
    // fov 40 is that of the shorter (horizontal) side: vfov = 2 atan(tan 20° · 64/48).
    let vfov = 2.0 * (20f32.to_radians().tan() * 64.0 / 48.0).atan().to_degrees();
    assert!((s.camera.vfov - vfov).abs() < 1e-3, "{} vs {vfov}", s.camera.vfov);
    assert_eq!(s.camera.from, Vec3::new(0.0, 1.0, 6.0));
    // Two spheres; the floor (2) + the textured quad (2) + the light (2) + the PLY bunny.
    assert_eq!(s.geometry.spheres.len(), 2);
    assert_eq!(s.geometry.triangle_count(), 2 + 2 + 2 + 4968);
    // Lights: the point light (I · scale) and the distant one; the area light emits 4.
    assert_eq!(s.lights.len(), 2);
    assert!(s.lights.iter().any(|l| matches!(l, raylab_render::Light::Point { intensity, .. } if *intensity == Rgb::splat(10.0))));
    assert_eq!(s.area_lights.len(), 2);
    assert!(s.environment.is_some());
    // Named materials, the coated diffuse and the MTL-free default: names are kept.
    assert!(s.material_names.iter().any(|n| n == "gold") && s.material_names.iter().any(|n| n == "glass"));
    assert_eq!(s.textures.len(), 2);
    // It renders, and not to black.
    let small = load_scene_or_mesh(&data().join("every_directive.pbrt"), &Overrides { width: Some(24), height: Some(32), spp: Some(4), ..Default::default() }).unwrap();
    assert!(mean(&pixels(&small)) > 0.01);
}

/// pbrt's camera space is left-handed: a plain LookAt shows the world mirrored compared
/// with raylab's camera, so the loader mirrors the world to give pbrt's image.
#[test]
fn a_plain_pbrt_look_at_gives_pbrts_image_not_its_mirror() {
    let dir = std::env::temp_dir().join(format!("raylab_pbrt_mirror_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = |prefix: &str| {
        let path = dir.join("s.pbrt");
        std::fs::write(&path, format!("{prefix}LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nTranslate -1 0 0\nShape \"sphere\" \"float radius\" 0.5\n")).unwrap();
        load_scene_or_mesh(&path, &Overrides::default()).unwrap()
    };
    // pbrt's image x axis is up × forward = Y × -Z = -X: the sphere at x = -1 is on the
    // right of pbrt's image, so on raylab's right (+x seen from +z) after the mirror.
    let plain = scene("");
    assert!(plain.geometry.spheres[0].bounds().centroid().x > 0.9, "{:?}", plain.geometry.spheres[0].bounds());
    // With `Scale -1 1 1` (Blender's exporter) pbrt's camera is right-handed: no mirror.
    let exported = scene("Scale -1 1 1\n");
    assert!(exported.geometry.spheres[0].bounds().centroid().x < -0.9);
    std::fs::remove_dir_all(&dir).ok();
}

fn pbrt_error(src: &str, lenient: bool) -> Result<Vec<String>, String> {
    let dir = std::env::temp_dir().join(format!("raylab_pbrt_err_{}_{}", std::process::id(), src.len()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.pbrt");
    std::fs::write(&path, src).unwrap();
    let r = raylab_loader::parse_any(&path, lenient).map(|d| d.warnings).map_err(|e| e.to_string().replace(&dir.display().to_string(), "DIR"));
    std::fs::remove_dir_all(&dir).ok();
    r.map(|w| w.into_iter().map(|s| s.replace(&dir.display().to_string(), "DIR")).collect())
}

const CAMERA: &str = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n";

#[test]
fn pbrt_outside_the_subset_is_an_error_naming_file_line_and_directive() {
    let src = format!("{CAMERA}MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nShape \"sphere\"\n");
    assert_eq!(
        pbrt_error(&src, false).unwrap_err(),
        format!("DIR/bad.pbrt:4: MakeNamedMedium: unknown or unsupported directive `MakeNamedMedium` (supported: LookAt, Camera, Film, Sampler, Integrator, WorldBegin, Identity, Translate, Rotate, Scale, Transform, ConcatTransform, AttributeBegin, AttributeEnd, Include, Import, Shape, Material, MakeNamedMaterial, NamedMaterial, Texture, LightSource, AreaLightSource) (raylab reads a subset of pbrt-v4; see docs/scene-format.md)")
    );
    // --lenient: a warning, and the rest is read.
    let warnings = pbrt_error(&src, true).unwrap();
    assert_eq!(warnings.len(), 1);
    assert!(warnings[0].starts_with("DIR/bad.pbrt:4: MakeNamedMedium: unknown or unsupported directive") && warnings[0].ends_with("; skipped"), "{}", warnings[0]);
    assert_eq!(
        pbrt_error(&format!("{CAMERA}Shape \"curve\" \"point3 P\" [ 0 0 0 1 1 1 2 2 2 3 3 3 ]\n"), false).unwrap_err(),
        "DIR/bad.pbrt:4: Shape: shape \"curve\" is not supported (supported: trianglemesh, plymesh, sphere, bilinearmesh) (raylab reads a subset of pbrt-v4; see docs/scene-format.md)"
    );
    assert_eq!(
        pbrt_error(&format!("{CAMERA}Shape \"sphere\" \"float radius\" 1 \"float zmin\" -0.5\n"), false).unwrap_err(),
        "DIR/bad.pbrt:4: Shape: parameter \"float zmin\" is not supported (raylab reads a subset of pbrt-v4; see docs/scene-format.md)"
    );
    assert_eq!(pbrt_error(&format!("{CAMERA}\nTranslate 1 2\n"), false).unwrap_err(), "DIR/bad.pbrt:5: Translate: expected 3 numbers, found 2");
    assert_eq!(pbrt_error(&format!("{CAMERA}Include \"nowhere.pbrt\"\n"), false).unwrap_err().split(" (looked in").next().unwrap(), "DIR/bad.pbrt:4: Include: cannot find `nowhere.pbrt`");
    assert_eq!(pbrt_error("WorldBegin\n", false).unwrap_err(), "DIR/bad.pbrt: no `Camera` directive before `WorldBegin` (raylab needs one)");
}

#[test]
fn unknown_extensions_and_empty_meshes_are_errors() {
    let e = load_scene_or_mesh(Path::new("scene.xml"), &Overrides::default()).unwrap_err().to_string();
    assert_eq!(e, "scene.xml: unsupported file type (supported: .toml, .pbrt, .gltf, .glb, .obj, .obj.gz, .ply, .ply.gz)");
    let src = "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n[[shapes]]\ntype = \"mesh\"\nfile = \"bunny.stl\"\n";
    let e = load_scene_str(src, Path::new("s.toml"), &Resolver::Disk { base: data() }, &Overrides::default()).unwrap_err().to_string();
    assert_eq!(e, "s.toml:7: shapes[0].file: unsupported mesh format `bunny.stl` (supported: .obj, .obj.gz, .ply, .ply.gz)");
    // A PLY with vertices and no faces loads 0 triangles: an error, not a black image.
    let dir = std::env::temp_dir().join(format!("raylab_empty_ply_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ply = dir.join("empty.ply");
    std::fs::write(&ply, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n").unwrap();
    let e = load_scene_or_mesh(&ply, &Overrides::default()).unwrap_err().to_string();
    assert_eq!(e, format!("{}: the mesh has no triangles", ply.display()));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_bare_glb_from_trimesh_is_framed_like_the_obj() {
    let o = Overrides { width: Some(48), height: Some(36), ..Default::default() };
    let obj = load_scene_or_mesh(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/bunny_4968.obj"), &o).unwrap();
    let glb = load_scene_or_mesh(&data().join("bunny.glb"), &o).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(glb.geometry.triangle_count(), 4968);
    assert!((glb.camera.from - obj.camera.from).length() < 1e-5, "{} vs {}", glb.camera.from, obj.camera.from);
    let e = mse(&pixels(&obj), &pixels(&glb));
    assert!(e < 1e-4, "MSE {e}");
}

/// A hand-written glTF: node transforms, a camera, a KHR point light and a metallic material.
#[test]
fn gltf_nodes_camera_light_and_material_map_as_documented() {
    let dir = std::env::temp_dir().join(format!("raylab_gltf_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bin: Vec<u8> = [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join("tri.bin"), &bin).unwrap();
    let json = r#"{
      "asset": {"version": "2.0"},
      "extensionsUsed": ["KHR_lights_punctual"],
      "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1, 0.5, 0.25], "intensity": 10}]}},
      "scene": 0,
      "scenes": [{"nodes": [0, 1, 2]}],
      "nodes": [
        {"mesh": 0, "translation": [1, 0, 0], "scale": [2, 2, 2]},
        {"camera": 0, "translation": [0, 0, 5]},
        {"translation": [0, 3, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}}
      ],
      "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
      "materials": [{"name": "gold-ish", "pbrMetallicRoughness": {"baseColorFactor": [1, 0.8, 0.4, 1], "metallicFactor": 1, "roughnessFactor": 0.5}}],
      "buffers": [{"uri": "tri.bin", "byteLength": 36}],
      "bufferViews": [{"buffer": 0, "byteLength": 36}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]
    }"#;
    std::fs::write(dir.join("tri.gltf"), json).unwrap();
    let s = load_scene_or_mesh(&dir.join("tri.gltf"), &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(s.geometry.meshes[0].positions, vec![Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0), Vec3::new(1.0, 2.0, 0.0)]);
    assert_eq!(s.camera.from, Vec3::new(0.0, 0.0, 5.0));
    assert!((s.camera.vfov - 0.5f32.to_degrees()).abs() < 1e-4);
    assert_eq!(s.lights.len(), 1);
    assert!(matches!(s.lights[0], raylab_render::Light::Point { position, intensity } if position == Vec3::new(0.0, 3.0, 0.0) && intensity == Rgb::new(10.0, 5.0, 2.5)));
    let m = s.geometry.meshes[0].material;
    assert_eq!(s.material_names[m.0 as usize], "gold-ish");
    // glTF's own BRDF: fully metallic, so no diffuse, f0 = base colour, α = roughness².
    let mat = &s.materials[m.0 as usize];
    assert_eq!(*mat, Material::MetallicRoughness { base_color: TexColor::Constant(Rgb::new(1.0, 0.8, 0.4)), metallic: 1.0, roughness: 0.5, metallic_roughness: None });
    assert_cook_torrance(mat.bsdf(&s.textures, raylab_core::Vec2::ZERO, Vec3::ZERO), Rgb::ZERO, Rgb::new(1.0, 0.8, 0.4), 0.25);
}

/// The BSDF is glTF's: Cook–Torrance with GGX–Smith, Schlick's Fresnel from `f0`, and the
/// given diffuse colour and α.
fn assert_cook_torrance(bsdf: raylab_render::bsdf::Bsdf, diffuse: Rgb, f0: Rgb, alpha: f32) {
    use raylab_render::bsdf::{Bsdf, Distribution, Fresnel, Geometry};
    match bsdf {
        Bsdf::CookTorrance { diffuse: d, specular, alpha: a, distribution: Distribution::Ggx, geometry: Geometry::Smith, fresnel: Fresnel::Schlick(f) } => {
            assert!((d - diffuse).abs().max_element() < 1e-6, "diffuse {d} vs {diffuse}");
            assert!((f - f0).abs().max_element() < 1e-6, "f0 {f} vs {f0}");
            assert!((a - alpha).abs() < 1e-6, "alpha {a} vs {alpha}");
            assert_eq!(specular, Rgb::ONE);
        }
        other => panic!("{other:?}"),
    }
}

/// A metallic-roughness texture (linear data: green = roughness, blue = metalness) scales the
/// factors per shading point; the base-colour factor multiplies the base-colour texture; an
/// occlusion texture and alpha masks are ignored with a warning.
#[test]
fn gltf_metallic_roughness_textures_vary_the_brdf_per_point() {
    let dir = std::env::temp_dir().join(format!("raylab_gltf_mr_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Base colour sRGB 188; red (occlusion in packed ORM textures) 255, roughness 102/255 = 0.4, metalness 51/255 = 0.2.
    let material = r#"{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [1, 0.5, 0.25, 1],
                      "metallicRoughnessTexture": {"index": 1}, "metallicFactor": 1, "roughnessFactor": 0.5},
                     "occlusionTexture": {"index": 1}, "alphaMode": "MASK"}"#;
    let (json, _) = textured_triangle_gltf(material, [png_1x1([188, 188, 188]), png_1x1([255, 102, 51])]);
    let path = dir.join("orm.gltf");
    std::fs::write(&path, &json).unwrap();
    let desc = raylab_loader::parse_any(&path, false).unwrap_or_else(|e| panic!("{e}"));
    let p = path.display();
    assert_eq!(
        desc.warnings,
        vec![
            format!("{p}: materials[0].occlusionTexture is ignored (the path tracer computes occlusion)"),
            format!("{p}: materials[0].alphaMode MASK is read as OPAQUE (raylab has no alpha cut-outs or transparency)"),
        ]
    );
    let s = raylab_loader::build_scene(desc, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
    std::fs::remove_dir_all(&dir).ok();
    let m = &s.materials[s.geometry.meshes[0].material.0 as usize];
    let Material::MetallicRoughness { metallic, roughness, metallic_roughness: Some(_), .. } = m else { panic!("{m:?}") };
    assert_eq!((*metallic, *roughness), (1.0, 0.5));
    // Texel values by hand: base = sRGB 188 (linear 0.50289) × factor; metalness 1 × 0.2;
    // roughness 0.5 × 0.4 = 0.2, α = 0.04; diffuse = base·(1 - 0.2); f0 = 0.04 + (base - 0.04)·0.2.
    // The data texture is read linear: decoded as sRGB, 102 would be 0.133, not 0.4.
    let base = Rgb::new(1.0, 0.5, 0.25) * 0.502886;
    let bsdf = m.bsdf(&s.textures, raylab_core::Vec2::new(0.3, 0.3), Vec3::ZERO);
    assert_cook_torrance(bsdf, base * 0.8, Rgb::splat(0.04) + (base - Rgb::splat(0.04)) * 0.2, 0.04);
}

/// A glTF of one unit right triangle with UVs, its buffer and two PNG images embedded as
/// base64 `data:` URIs (textures 0 and 1), and `material` as its only material; returns the
/// JSON and the buffer's base64 text.
fn textured_triangle_gltf(material: &str, images: [Vec<u8>; 2]) -> (String, String) {
    let positions: Vec<u8> = [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let uvs: Vec<u8> = [[0f32, 1.0], [1.0, 1.0], [0.0, 0.0]].iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let buffer = base64::encode([positions, uvs].concat());
    let [image0, image1] = images.map(base64::encode);
    let json = format!(
        r#"{{
      "asset": {{"version": "2.0"}},
      "scenes": [{{"nodes": [0]}}],
      "nodes": [{{"mesh": 0}}],
      "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "material": 0}}]}}],
      "materials": [{material}],
      "textures": [{{"source": 0}}, {{"source": 1}}],
      "images": [{{"uri": "data:image/png;base64,{image0}"}}, {{"uri": "data:image/png;base64,{image1}"}}],
      "buffers": [{{"uri": "data:application/octet-stream;base64,{buffer}", "byteLength": 60}}],
      "bufferViews": [{{"buffer": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 24}}],
      "accessors": [
        {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
        {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}}
      ]
    }}"#
    );
    (json, buffer)
}

/// A 1×1 PNG of one 8-bit colour, as exporters embed images.
fn png_1x1(rgb: [u8; 3]) -> Vec<u8> {
    let mut out = Vec::new();
    image::ImageEncoder::write_image(image::codecs::png::PngEncoder::new(&mut out), &rgb, 1, 1, image::ExtendedColorType::Rgb8).unwrap();
    out
}

/// A hand-written glTF with everything embedded as base64 `data:` URIs (buffer and images),
/// a base-colour texture and a normal texture: the normal map is read linear (not as sRGB)
/// and becomes the material's tangent-space normal map; the base colour is decoded from sRGB.
#[test]
fn gltf_data_uris_and_normal_textures() {
    let dir = std::env::temp_dir().join(format!("raylab_gltf_data_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let material = r#"{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}, "normalTexture": {"index": 1}}"#;
    let (json, buffer) = textured_triangle_gltf(material, [png_1x1([188, 188, 188]), png_1x1([128, 128, 255])]);
    std::fs::write(dir.join("embedded.gltf"), &json).unwrap();
    let s = load_scene_or_mesh(&dir.join("embedded.gltf"), &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
    let mesh = &s.geometry.meshes[0];
    assert_eq!(mesh.positions, vec![Vec3::ZERO, Vec3::X, Vec3::Y]);
    // glTF's v runs down: flipped on load.
    assert_eq!(mesh.uvs, vec![raylab_core::Vec2::new(0.0, 0.0), raylab_core::Vec2::new(1.0, 0.0), raylab_core::Vec2::new(0.0, 1.0)]);
    assert_eq!(mesh.tangents.len(), 3, "a tangent-space normal map needs tangents, computed from the UVs");
    let m = mesh.material.0 as usize;
    let texel = |id: raylab_render::TextureId| match &s.textures[id.0 as usize] {
        raylab_render::Texture::Image(i) => i.texels()[0],
        other => panic!("{other:?}"),
    };
    match s.material_perturbations[m] {
        Some(raylab_render::shading::ShadingPerturbation::NormalMap { texture, space: raylab_render::shading::NormalSpace::Tangent }) => {
            assert_eq!(texel(texture), Rgb::new(128.0 / 255.0, 128.0 / 255.0, 1.0), "normal maps are linear data");
        }
        ref other => panic!("{other:?}"),
    }
    match &s.materials[m] {
        // metallic 0 and the default roughness 1: diffuse.
        raylab_render::Material::Diffuse { albedo: raylab_render::material::TexColor::Texture(t) } => {
            // sRGB 188 is linear 0.5029.
            assert!((texel(*t).x - 0.5029).abs() < 1e-3, "{}", texel(*t));
        }
        other => panic!("{other:?}"),
    }
    // Percent-encoded data URIs are not base64: said plainly.
    std::fs::write(dir.join("plain.gltf"), json.replace(&format!("data:application/octet-stream;base64,{buffer}"), "data:text/plain,abc")).unwrap();
    let e = load_scene_or_mesh(&dir.join("plain.gltf"), &Overrides::default()).unwrap_err().to_string();
    assert_eq!(e, format!("{}: buffers[0]: only base64 data URIs are supported, found `data:text/plain,...`", dir.join("plain.gltf").display()));
    std::fs::remove_dir_all(&dir).ok();
}

/// pbrt-v4's `infinite` light with a `filename`: an equal-area octahedral square in the
/// light's space, resampled into raylab's equirectangular map of the world. The map is red
/// on the light's +z hemisphere (the square's central diamond) and blue on the other; under
/// `Rotate -90 1 0 0` the light's +z is the world's +y, so the sky is red and the ground blue.
#[test]
fn pbrt_infinite_light_maps_are_equal_area_squares() {
    let dir = std::env::temp_dir().join(format!("raylab_pbrt_env_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let side = 32u32;
    let texels: Vec<u8> = (0..side * side)
        .flat_map(|k| {
            let (u, v) = (((k % side) as f32 + 0.5) / side as f32 * 2.0 - 1.0, ((k / side) as f32 + 0.5) / side as f32 * 2.0 - 1.0);
            if u.abs() + v.abs() < 1.0 { [255, 0, 0] } else { [0, 0, 255] }
        })
        .collect();
    image::save_buffer(dir.join("sky.png"), &texels, side, side, image::ExtendedColorType::Rgb8).unwrap();
    image::save_buffer(dir.join("wide.png"), &texels, 2 * side, side / 2, image::ExtendedColorType::Rgb8).unwrap();
    let scene = |file: &str| format!("LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\nWorldBegin\nAttributeBegin\nRotate -90 1 0 0\nLightSource \"infinite\" \"string filename\" \"{file}\"\nAttributeEnd\nShape \"sphere\" \"float radius\" 1\n");
    std::fs::write(dir.join("env.pbrt"), scene("sky.png")).unwrap();
    let desc = raylab_loader::pbrt::parse_pbrt(&dir.join("env.pbrt"), false).unwrap_or_else(|e| panic!("{e}"));
    let env = desc.environment.expect("an environment light");
    // (Not at the exact poles, where the equirect map's repeat wrap blends the first and last rows.)
    assert_eq!(env.radiance(Vec3::new(0.1, 0.99, 0.05).normalize()), Rgb::X);
    assert_eq!(env.radiance(Vec3::new(-0.1, -0.99, 0.05).normalize()), Rgb::Z);
    assert_eq!(env.radiance(Vec3::new(0.3, 0.9, -0.3).normalize()), Rgb::X);
    assert_eq!(env.radiance(Vec3::new(-0.5, -0.6, 0.2).normalize()), Rgb::Z);
    // Below the horizon though towards the world's +z (the light's +z, were the rotation ignored).
    assert_eq!(env.radiance(Vec3::new(0.05, -0.3, 0.95).normalize()), Rgb::Z);
    std::fs::write(dir.join("wide.pbrt"), scene("wide.png")).unwrap();
    let e = raylab_loader::pbrt::parse_pbrt(&dir.join("wide.pbrt"), false).unwrap_err().to_string();
    assert_eq!(e, format!("{}:6: LightSource: wide.png: pbrt-v4 environment maps are equal-area octahedral squares, this image is 64×16 (pbrt-v4's `imgtool makeequiarea` converts an equirectangular map)", dir.join("wide.pbrt").display()));
    std::fs::remove_dir_all(&dir).ok();
}

/// A `KHR_lights_punctual` spot light on a node turned to face down: a `Light::Spot` at the
/// node, along its -z, with the file's cone angles; it lights a point straight below like a
/// point light of the same intensity.
#[test]
fn gltf_spot_lights_shine_along_the_nodes_minus_z() {
    let dir = std::env::temp_dir().join(format!("raylab_gltf_spot_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bin: Vec<u8> = [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let json = format!(
        r#"{{
      "asset": {{"version": "2.0"}},
      "extensionsUsed": ["KHR_lights_punctual"],
      "extensions": {{"KHR_lights_punctual": {{"lights": [{{"type": "spot", "color": [1, 1, 1], "intensity": 8, "spot": {{"innerConeAngle": 0.3, "outerConeAngle": 0.6}}}}]}}}},
      "scenes": [{{"nodes": [0, 1]}}],
      "nodes": [
        {{"mesh": 0}},
        {{"translation": [0, 2, 0], "rotation": [-0.70710677, 0, 0, 0.70710677], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}}
      ],
      "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
      "buffers": [{{"uri": "data:application/octet-stream;base64,{}", "byteLength": 36}}],
      "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
      "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}}]
    }}"#,
        base64::encode(&bin)
    );
    std::fs::write(dir.join("spot.gltf"), json).unwrap();
    let s = load_scene_or_mesh(&dir.join("spot.gltf"), &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(s.lights.len(), 1, "the file's light replaces the framing light");
    let raylab_render::Light::Spot { position, direction, intensity, cos_inner, cos_outer } = s.lights[0] else { panic!("{:?}", s.lights[0]) };
    assert!((position - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-6 && (direction + Vec3::Y).length() < 1e-6, "{position} {direction}");
    assert_eq!((intensity, cos_inner, cos_outer), (Rgb::splat(8.0), 0.3f32.cos(), 0.6f32.cos()));
    let below = s.lights[0].sample(Vec3::ZERO, 0, raylab_core::Vec2::ZERO).unwrap();
    assert!((below.irradiance - Rgb::splat(2.0)).length() < 1e-5, "{}", below.irradiance);
    assert!(s.lights[0].sample(Vec3::new(3.0, 1.9, 0.0), 0, raylab_core::Vec2::ZERO).is_none(), "outside the outer cone");
}
