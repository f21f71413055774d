//! The glTF 2.0 front end (`.gltf` with its `.bin`, and `.glb`), through the `gltf` crate:
//! the default scene's node hierarchy and transforms, triangle meshes (positions, normals,
//! first UV set), the metallic-roughness material mapped to raylab's materials (table in
//! `docs/scene-format.md`), base-colour, metallic-roughness and (tangent-space) normal textures, perspective
//! cameras and `KHR_lights_punctual` (point, directional, spot); buffers and images in files, in the GLB's binary
//! chunk or in base64 `data:` URIs. Without a camera the model is framed as a bare mesh is.

use std::collections::HashMap;
use std::path::Path;

use raylab_core::{Rgb, Transform, Vec2, Vec3};
use raylab_render::material::TexColor;
use raylab_render::shading::{NormalSpace, ShadingPerturbation};
use raylab_render::texture::{Filter, ImageTexture, Wrap};
use raylab_render::{Light, Material, MaterialId, Texture, TextureId, TriangleMesh};

use crate::description::{CameraDescription, SceneDescription, Span};
use crate::error::LoadError;
use crate::files::{read_capped, MAX_DATA_BYTES};

/// Reads a glTF or GLB file (and the buffers and images it names) into a description.
pub fn parse_gltf(path: &Path) -> Result<SceneDescription, LoadError> {
    let bytes = read_capped(path, MAX_DATA_BYTES)?;
    let doc = gltf::Gltf::from_slice(&bytes).map_err(|e| LoadError::file(path, format!("not a valid glTF 2.0 file: {e}")))?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let read_uri = |what: &str, uri: &str| -> Result<Vec<u8>, LoadError> {
        if let Some(data) = uri.strip_prefix("data:") {
            return data_uri(data).map_err(|e| LoadError::new(path, None, what, e));
        }
        let file = base.join(uri.replace("%20", " "));
        read_capped(&file, MAX_DATA_BYTES).map_err(|e| LoadError::new(path, None, what, e.to_string()))
    };
    let mut buffers = Vec::new();
    for b in doc.buffers() {
        buffers.push(match b.source() {
            gltf::buffer::Source::Bin => doc.blob.clone().ok_or_else(|| LoadError::new(path, None, format!("buffers[{}]", b.index()), "the GLB has no binary chunk"))?,
            gltf::buffer::Source::Uri(uri) => read_uri(&format!("buffers[{}]", b.index()), uri)?,
        });
    }

    // Meshes and camera first; the description is made once the camera (or framing) is known.
    let mut meshes: Vec<(TriangleMesh, Option<usize>)> = Vec::new();
    let mut camera = None;
    let mut lights = Vec::new();
    let scene = doc.default_scene().or_else(|| doc.scenes().next()).ok_or_else(|| LoadError::file(path, "the file has no scene"))?;
    let mut stack: Vec<(gltf::Node, glam::Mat4)> = scene.nodes().map(|n| (n, glam::Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let world = parent * glam::Mat4::from_cols_array_2d(&node.transform().matrix());
        let field = format!("nodes[{}]", node.index());
        let to_world = Transform::from_affine(glam::Affine3A::from_mat4(world)).ok_or_else(|| LoadError::new(path, None, field.clone(), "the node's transform is singular"))?;
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let pfield = format!("meshes[{}].primitives[{}]", mesh.index(), prim.index());
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    return Err(LoadError::new(path, None, pfield, format!("mode {:?} is not supported (only triangles)", prim.mode())));
                }
                use gltf::Semantic;
                // Output bytes per value: positions and normals 12, UVs 8, indices 4 read then 4 as triangles.
                for (a, size) in [(prim.get(&Semantic::Positions), 12), (prim.get(&Semantic::Normals), 12), (prim.get(&Semantic::TexCoords(0)), 8), (prim.indices(), 8)] {
                    if let Some(a) = a {
                        check_accessor(&a, size).map_err(|e| LoadError::new(path, None, pfield.clone(), e))?;
                    }
                }
                let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
                let positions: Vec<Vec3> = reader.read_positions().ok_or_else(|| LoadError::new(path, None, pfield.clone(), "has no POSITION"))?.map(|p| to_world.point(Vec3::from_array(p))).collect();
                let indices: Vec<u32> = match reader.read_indices() {
                    Some(i) => i.into_u32().collect(),
                    None => (0..positions.len() as u32).collect(),
                };
                if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
                    return Err(LoadError::new(path, None, pfield, format!("index {bad} out of range ({} vertices)", positions.len())));
                }
                let normals = reader.read_normals().map(|n| n.map(|n| to_world.normal(Vec3::from_array(n)).normalize_or_zero()).collect()).unwrap_or_default();
                let uvs = reader.read_tex_coords(0).map(|t| t.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect()).unwrap_or_default();
                let name = mesh.name().unwrap_or("gltf mesh").to_string();
                let m = TriangleMesh { name, positions, normals, uvs, indices: indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(), object_to_world: to_world, ..Default::default() };
                meshes.push((m, prim.material().index()));
            }
        }
        if let (Some(cam), None) = (node.camera(), &camera) {
            let gltf::camera::Projection::Perspective(p) = cam.projection() else {
                return Err(LoadError::new(path, None, field, "orthographic cameras are not supported"));
            };
            // glTF cameras look down their local -z with +y up.
            let from = world.transform_point3(Vec3::ZERO);
            let span = Span::new(path, None, format!("cameras[{}]", cam.index()));
            camera = Some(CameraDescription { from, at: from + world.transform_vector3(-Vec3::Z), up: world.transform_vector3(Vec3::Y), vfov: p.yfov().to_degrees(), aperture: 0.0, focus_distance: None, at_span: span.clone(), up_span: span });
        }
        if let Some(light) = node.light() {
            let c = Rgb::from_array(light.color()) * light.intensity();
            lights.push(match light.kind() {
                // Candela (lm/sr) is an intensity per steradian: raylab's point intensity.
                gltf::khr_lights_punctual::Kind::Point => Light::Point { position: world.transform_point3(Vec3::ZERO), intensity: c },
                // Lux is an irradiance.
                gltf::khr_lights_punctual::Kind::Directional => Light::Directional { direction: world.transform_vector3(-Vec3::Z).normalize(), irradiance: c },
                // Candela within the cone, along the node's -z; the extension's defaults are
                // an inner cone of 0 and an outer one of π/4.
                gltf::khr_lights_punctual::Kind::Spot { inner_cone_angle, outer_cone_angle } => Light::Spot {
                    position: world.transform_point3(Vec3::ZERO),
                    direction: world.transform_vector3(-Vec3::Z).normalize(),
                    intensity: c,
                    cos_inner: inner_cone_angle.cos(),
                    cos_outer: outer_cone_angle.cos(),
                },
            });
        }
        stack.extend(node.children().map(|c| (c, world)));
    }
    if meshes.iter().all(|(m, _)| m.indices.is_empty()) {
        return Err(LoadError::file(path, "the file has no triangles"));
    }
    let mut desc = match camera {
        Some(c) => SceneDescription::new(path, c),
        None => {
            let only: Vec<TriangleMesh> = meshes.iter().map(|(m, _)| m.clone()).collect();
            let mut d = crate::mesh_scene::framed_description(path, &only);
            if !lights.is_empty() {
                d.lights.clear();
            }
            d
        }
    };
    desc.lights.extend(lights);

    let mut material_ids: HashMap<usize, MaterialId> = HashMap::new();
    for (mut mesh, mat) in meshes {
        if let Some(k) = mat {
            let id = match material_ids.get(&k) {
                Some(&id) => id,
                None => {
                    let id = material(path, &doc, &buffers, &read_uri, k, &mut desc)?;
                    material_ids.insert(k, id);
                    id
                }
            };
            mesh.emission = Rgb::from_array(doc.materials().nth(k).map_or([0.0; 3], |m| m.emissive_factor()));
            mesh.material = id;
        }
        desc.geometry.add_mesh(mesh);
    }
    Ok(desc)
}

/// An accessor's count is the file's word: one that runs past its buffer view (the `gltf`
/// crate would read it as absent), is 0 (its reader would underflow), or whose values would
/// need more memory than this process may use (a sparse accessor without a view is `count`
/// zeros) is refused before the reader allocates.
fn check_accessor(a: &gltf::Accessor, out_size: u64) -> Result<(), String> {
    let (i, count) = (a.index(), a.count());
    if count == 0 {
        return Err(format!("accessors[{i}] has a count of 0"));
    }
    if let (Some(view), None) = (a.view(), a.sparse()) {
        let stride = view.stride().unwrap_or(a.size());
        let end = stride.checked_mul(count - 1).and_then(|b| b.checked_add(a.offset() + a.size()));
        if end.is_none_or(|end| end > view.length()) {
            return Err(format!("accessors[{i}]: {count} values run past bufferViews[{}] ({} bytes)", view.index(), view.length()));
        }
    }
    raylab_render::memory_guard::check(&format!("accessors[{i}] ({count} values)"), (count as u64).checked_mul(out_size))
}

/// The bytes of a `data:` URI (after `data:`): `[<media type>];base64,<payload>`, as glTF
/// exporters embed buffers and images.
fn data_uri(data: &str) -> Result<Vec<u8>, String> {
    let (header, payload) = data.split_once(',').ok_or("a data URI needs a `,` before its payload")?;
    if !header.ends_with(";base64") {
        return Err(format!("only base64 data URIs are supported, found `data:{header},...`"));
    }
    base64::decode(payload.trim()).map_err(|e| format!("the base64 payload of `data:{header},...` does not decode: {e}"))
}

/// Reads a URI (relative to the file, for the field named) into bytes.
type ReadUri<'a> = dyn Fn(&str, &str) -> Result<Vec<u8>, LoadError> + 'a;

/// An image texture of the file, its texels times `scale`: decoded from sRGB for colours,
/// linear for data (normals, metalness and roughness).
#[allow(clippy::too_many_arguments)]
fn image_texture(path: &Path, buffers: &[Vec<u8>], read_uri: &ReadUri<'_>, texture: gltf::Texture, srgb: bool, scale: Rgb, field: &str) -> Result<ImageTexture, LoadError> {
    let bytes = match texture.source().source() {
        gltf::image::Source::View { view, .. } => {
            let buffer = &buffers[view.buffer().index()];
            buffer.get(view.offset()..view.offset() + view.length()).ok_or_else(|| LoadError::new(path, None, field, format!("bufferViews[{}] runs past its buffer ({} bytes)", view.index(), buffer.len())))?.to_vec()
        }
        gltf::image::Source::Uri { uri, .. } => read_uri(field, uri)?,
    };
    let (w, h, mut texels) = crate::image_io::decode_image(path, &bytes, srgb).map_err(|e| LoadError::new(path, None, field, e.to_string()))?;
    if scale != Rgb::ONE {
        texels.iter_mut().for_each(|t| *t *= scale);
    }
    ImageTexture::new(w, h, texels, Wrap::Repeat, Filter::Bilinear).map_err(|e| LoadError::new(path, None, field, e.to_string()))
}

/// Maps a metallic-roughness material: a rough dielectric without a metallic-roughness
/// texture (metallic 0, roughness 1) is `diffuse`; anything else raylab's
/// `metallic-roughness` material, the glTF BRDF itself (Cook–Torrance with diffuse
/// `base·(1 - metallic)`, `f0 = lerp(0.04, base, metallic)`, GGX α = roughness²), with the
/// metallic-roughness texture read per shading point. The base-colour factor multiplies the
/// texture's texels on load (exact: filtering is linear).
fn material(path: &Path, doc: &gltf::Gltf, buffers: &[Vec<u8>], read_uri: &ReadUri<'_>, k: usize, desc: &mut SceneDescription) -> Result<MaterialId, LoadError> {
    let m = doc.materials().nth(k).expect("index from the file");
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor();
    let base = Rgb::new(r, g, b);
    let (metallic, roughness) = (pbr.metallic_factor(), pbr.roughness_factor());
    let field = format!("materials[{k}]");
    let texture = |info: gltf::texture::Info, srgb: bool, scale: Rgb, name: String, desc: &mut SceneDescription| -> Result<TextureId, LoadError> {
        if info.tex_coord() != 0 {
            desc.warnings.push(format!("{}: {name}: texCoord {} is read as 0 (raylab keeps the first UV set)", path.display(), info.tex_coord()));
        }
        let tex = image_texture(path, buffers, read_uri, info.texture(), srgb, scale, &name)?;
        Ok(desc.add_texture(name, Texture::Image(tex)))
    };
    let base_color = match pbr.base_color_texture() {
        Some(info) => TexColor::Texture(texture(info, true, base, format!("{field}.baseColorTexture"), desc)?),
        None => TexColor::Constant(base),
    };
    let metallic_roughness = pbr.metallic_roughness_texture().map(|info| texture(info, false, Rgb::ONE, format!("{field}.metallicRoughnessTexture"), desc)).transpose()?;
    // Ambient occlusion is what a path tracer computes; a baked copy would count it twice.
    if m.occlusion_texture().is_some() {
        desc.warnings.push(format!("{}: {field}.occlusionTexture is ignored (the path tracer computes occlusion)", path.display()));
    }
    let alpha = match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => None,
        gltf::material::AlphaMode::Mask => Some("MASK"),
        gltf::material::AlphaMode::Blend => Some("BLEND"),
    };
    if let Some(mode) = alpha {
        desc.warnings.push(format!("{}: {field}.alphaMode {mode} is read as OPAQUE (raylab has no alpha cut-outs or transparency)", path.display()));
    }
    let material = if metallic == 0.0 && roughness >= 1.0 && metallic_roughness.is_none() {
        Material::Diffuse { albedo: base_color }
    } else {
        Material::MetallicRoughness { base_color, metallic, roughness, metallic_roughness }
    };
    let name = m.name().map_or_else(|| field.clone(), str::to_string);
    let id = desc.add_material(name, material);
    // A tangent-space normal map, OpenGL's convention (+y up, as raylab's with glTF's v flipped
    // on load); tangents come from the UVs (MikkTSpace's convention) when the mesh is built.
    if let Some(normal) = m.normal_texture() {
        let nfield = format!("{field}.normalTexture");
        if normal.scale() != 1.0 {
            desc.warnings.push(format!("{}: {nfield}: scale {} is read as 1", path.display(), normal.scale()));
        }
        let tex = image_texture(path, buffers, read_uri, normal.texture(), false, Rgb::ONE, &nfield)?;
        let texture = desc.add_texture(nfield, Texture::Image(tex));
        desc.material_perturbations[id.0 as usize] = Some(ShadingPerturbation::NormalMap { texture, space: NormalSpace::Tangent });
    }
    Ok(id)
}
