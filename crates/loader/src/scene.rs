//! Scene files (TOML) to [`Scene`]s. The format is documented in `docs/scene-format.md`.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use raylab_core::{Rgb, Transform, Vec2, Vec3};
use raylab_render::bsdf::{Distribution, Geometry as MicrofacetGeometry};
use raylab_render::light::EnvironmentLight;
use raylab_render::material::{TexColor, METALS};
use raylab_render::shading::{NormalSpace, ShadingPerturbation};
use raylab_render::shape::bezier_patch::DEFAULT_SUBDIVISIONS;
use raylab_render::shape::{PatchSurfaces, DEFAULT_SEED_GRID};
use raylab_render::shape::Sphere;
use raylab_render::texture::{Checker, CheckerSpace, Filter, ImageTexture, Noise, NoiseKind, Wrap};
use raylab_render::settings::{SettingKind, SettingValue, SETTINGS};
use raylab_render::{Background, Light, Material, MaterialId, Scene, Texture, TextureId, TriangleMesh};
pub use raylab_render::Overrides;

use crate::description::{CameraDescription, SceneDescription, Span};

use crate::error::LoadError;
use crate::files::{not_found_message, Found, Resolver};
use crate::mesh_scene::load_mesh_file;
use crate::obj::{mtl_color, MtlMaterial};
use crate::patches::{load_patch_mesh, load_patches_world};
use crate::toml_read::{in_range, in_range_f32, positive, Doc, Table, Val};

const TOP: &[&str] = &["camera", "render", "background", "textures", "materials", "shapes", "lights"];
const CAMERA: &[&str] = &["from", "at", "up", "vfov", "width", "height", "aperture", "focus_distance"];
/// The keys of `[render]`: the settings table's.
static RENDER: std::sync::LazyLock<Vec<&'static str>> = std::sync::LazyLock::new(|| SETTINGS.iter().filter(|s| s.table == "render").map(|s| s.key).collect());
const BACKGROUND: &[&str] = &["color", "texture"];
const TEXTURE: &[&str] = &["name", "type", "file", "wrap", "filter", "srgb", "scale", "even", "odd", "space", "kind", "colors", "octaves", "seed", "color"];
const MATERIAL: &[&str] = &[
    "name", "type", "albedo", "ka", "kd", "ks", "exponent", "reflectance", "ior", "diffuse", "specular", "roughness", "distribution", "geometry", "f0", "metal", "eta", "k", "color",
    "base_color", "metallic", "metallic_roughness", "normal_map", "normal_space", "bump_map", "bump_scale",
];
/// Fields every material kind has.
const MATERIAL_COMMON: &[&str] = &["name", "type", "normal_map", "normal_space", "bump_map", "bump_scale"];
const SHAPE: &[&str] = &["type", "material", "transform", "center", "radius", "vertices", "normals", "uvs", "file", "smooth", "points", "basis", "degree", "mode", "segments", "sides", "crease_angle", "subdivisions"];
const LIGHT: &[&str] = &["type", "position", "intensity", "direction", "irradiance", "vertices", "radiance", "texture", "center", "radius", "n", "file", "scale"];
const TRANSFORM_STEP: &[&str] = &["scale", "rotate", "translate"];
const ROTATE: &[&str] = &["axis", "degrees"];

/// Reads a scene file and everything it names, and builds its acceleration structure.
pub fn load_scene(path: &Path, overrides: &Overrides) -> Result<Scene, LoadError> {
    let src = crate::files::read_text(path)?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    load_scene_str(&src, path, &Resolver::Disk { base }, overrides)
}

/// Parses scene text and builds it; `path` names it in messages, `resolver` finds the
/// files it names.
pub fn load_scene_str(src: &str, path: &Path, resolver: &Resolver, overrides: &Overrides) -> Result<Scene, LoadError> {
    crate::build::build_scene(parse_scene_str(src, path, resolver)?, overrides)
}

/// The TOML front end: scene text to a [`SceneDescription`] (every file it names read).
pub fn parse_scene_str(src: &str, path: &Path, resolver: &Resolver) -> Result<SceneDescription, LoadError> {
    let doc = Doc::new(path, src);
    let root = doc.parse(src)?;
    let top = Table::new(&doc, String::new(), root.span(), root.get_ref(), TOP)?;
    let mut b = Builder {
        doc: &doc,
        resolver,
        texture_ids: HashMap::new(),
        srgb_textures: HashSet::new(),
        material_ids: HashMap::new(),
        mtl_cache: HashMap::new(),
        has_background: top.has("background"),
    };

    let camera = b.camera(&top)?;
    let mut scene = SceneDescription::new(path, camera);
    b.settings(&top, &mut scene)?;
    for t in top.tables("textures", TEXTURE)? {
        b.texture(&mut scene, &t)?;
    }
    for m in top.tables("materials", MATERIAL)? {
        b.material(&mut scene, &m)?;
    }
    if let Some(bg) = top.get("background") {
        scene.background = b.background(&mut scene, &bg.table(BACKGROUND)?)?;
    }
    for s in top.tables("shapes", SHAPE)? {
        b.shape(&mut scene, &s)?;
    }
    for l in top.tables("lights", LIGHT)? {
        b.light(&mut scene, &l)?;
    }
    Ok(scene)
}

/// The largest camera distance whose square single precision holds (with a margin).
const MAX_CAMERA_DISTANCE: f64 = 1e18;

/// Why a `scale` step has no inverse: a zero factor, or a volume change beyond single
/// precision (a scale of 1e13 cubes to 1e39).
fn scale_error(v: &Val, f: Vec3) -> LoadError {
    if f.cmpeq(Vec3::ZERO).any() {
        return v.err("scale must not be zero");
    }
    let det = f.x as f64 * f.y as f64 * f.z as f64;
    v.err(format!("scale [{:e}, {:e}, {:e}] changes volumes by {det:.1e}, beyond single precision (1e-30 to 3.4e38 in magnitude)", f.x, f.y, f.z))
}

struct Builder<'a> {
    doc: &'a Doc<'a>,
    resolver: &'a Resolver,
    texture_ids: HashMap<String, raylab_render::TextureId>,
    /// Image textures decoded from sRGB, which cannot hold normal maps.
    srgb_textures: HashSet<raylab_render::TextureId>,
    material_ids: HashMap<String, MaterialId>,
    /// MTL materials already converted, by (MTL path, index).
    mtl_cache: HashMap<(String, usize), MaterialId>,
    /// Whether the scene has a `[background]` table (an environment light replaces it).
    has_background: bool,
}

impl Builder<'_> {
    /// The `[render]` table and the image size of `[camera]`, as the file gives them: every
    /// key of the settings table ([`SETTINGS`]) read the same way.
    fn settings(&self, top: &Table, desc: &mut SceneDescription) -> Result<(), LoadError> {
        let render = top.get("render").map(|r| r.table(&RENDER)).transpose()?;
        let camera = top.get("camera").map(|c| c.table(CAMERA)).transpose()?;
        for spec in SETTINGS {
            let table = if spec.table == "camera" { camera.as_ref() } else { render.as_ref() };
            let Some(v) = table.and_then(|t| t.get(spec.key)) else { continue };
            let value = match spec.kind {
                SettingKind::Integer { .. } => SettingValue::Integer(v.integer()? as i128),
                SettingKind::Name(_) => SettingValue::Name(v.str()?),
            };
            desc.settings.set(spec.key, value).map_err(|e| v.err(e))?;
            if spec.key == "spp" {
                desc.spp_span = Some(self.span(&v));
            }
        }
        Ok(())
    }

    /// Where `v` is, for errors the builder reports.
    fn span(&self, v: &Val) -> Span {
        let e = v.err("");
        Span { file: e.file, line: e.line, field: e.field }
    }

    fn camera(&self, top: &Table) -> Result<CameraDescription, LoadError> {
        let c = top.req("camera")?.table(CAMERA)?;
        let from = c.req("from")?.vec3()?;
        let at_v = c.req("at")?;
        let at = at_v.vec3()?;
        let up_v = c.get("up");
        let up = up_v.as_ref().map(|v| v.vec3()).transpose()?.unwrap_or(Vec3::Y);
        let vfov_v = c.req("vfov")?;
        let vfov = vfov_v.f32()?;
        if !(vfov > 0.0 && vfov < 180.0) {
            return Err(vfov_v.err(format!("must be in (0, 180) degrees, found {vfov}")));
        }
        let aperture = c.opt("aperture", |v| v.f32())?.unwrap_or(0.0);
        if aperture < 0.0 {
            return Err(c.get("aperture").unwrap().err(format!("must not be negative, found {aperture}")));
        }
        let focus_distance = c.opt("focus_distance", |v| positive(v, v.f32()?))?;
        // Single precision squares the distance to aim the camera: beyond ~1e19 that
        // overflows, and Camera::new would wrongly say that `at` equals `from`.
        let distance = from.as_dvec3().distance(at.as_dvec3());
        if distance > MAX_CAMERA_DISTANCE {
            return Err(at_v.err(format!("is {distance:.1e} from camera.from, farther than single precision can aim a camera ({MAX_CAMERA_DISTANCE:e})")));
        }
        let at_span = self.span(&at_v);
        let up_span = up_v.as_ref().map_or_else(|| at_span.clone(), |v| self.span(v));
        Ok(CameraDescription { from, at, up, vfov, aperture, focus_distance, at_span, up_span })
    }

    fn find(&self, v: &Val) -> Result<Found, LoadError> {
        let name = v.str()?;
        self.resolver.find(name).map_err(|tried| v.err(not_found_message(name, &tried)))
    }

    fn image_texture(&self, v: &Val, found: &Found, srgb: bool, wrap: Wrap, filter: Filter) -> Result<ImageTexture, LoadError> {
        let (w, h, texels) = crate::image_io::read_image(&found.path(), srgb).map_err(|e| v.err(e.to_string()))?;
        ImageTexture::new(w, h, texels, wrap, filter).map_err(|e| v.err(format!("{}: {e}", found.path().display())))
    }

    fn texture(&mut self, scene: &mut SceneDescription, t: &Table) -> Result<(), LoadError> {
        let name_v = t.req("name")?;
        let name = name_v.str()?.to_string();
        if self.texture_ids.contains_key(&name) {
            return Err(name_v.err(format!("a texture named `{name}` already exists")));
        }
        let kind = t.type_name(&["image", "checker", "noise", "constant"])?;
        let only = |keys: &[&str]| -> Result<(), LoadError> {
            for k in TEXTURE {
                if !["name", "type"].contains(k) && !keys.contains(k) && t.has(k) {
                    return Err(t.get(k).unwrap().err(format!("not a field of `{kind}` textures (valid: name, type, {})", keys.join(", "))));
                }
            }
            Ok(())
        };
        let mut srgb = false;
        let tex = match kind {
            "image" => {
                only(&["file", "wrap", "filter", "srgb"])?;
                let file = t.req("file")?;
                let found = self.find(&file)?;
                let wrap = t.opt("wrap", |v| v.str()?.parse::<Wrap>().map_err(|e| v.err(e.to_string())))?.unwrap_or(Wrap::Repeat);
                let filter = t.opt("filter", |v| v.str()?.parse::<Filter>().map_err(|e| v.err(e.to_string())))?.unwrap_or(Filter::Bilinear);
                srgb = t.opt("srgb", |v| v.bool())?.unwrap_or(true);
                Texture::Image(self.image_texture(&file, &found, srgb, wrap, filter)?)
            }
            "checker" => {
                only(&["even", "odd", "scale", "space"])?;
                let even = t.opt("even", |v| v.color())?.unwrap_or(Rgb::splat(0.8));
                let odd = t.opt("odd", |v| v.color())?.unwrap_or(Rgb::splat(0.2));
                let scale = t.opt("scale", |v| positive(v, v.f32()?))?.unwrap_or(10.0);
                let space = t.opt("space", |v| v.str()?.parse::<CheckerSpace>().map_err(|e| v.err(e.to_string())))?.unwrap_or(CheckerSpace::Uv);
                Texture::Checker(Checker { even, odd, scale, space })
            }
            "noise" => {
                only(&["kind", "scale", "colors", "octaves", "seed"])?;
                let kind = t.opt("kind", |v| v.str()?.parse::<NoiseKind>().map_err(|e| v.err(e.to_string())))?.unwrap_or(NoiseKind::Marble);
                let scale = t.opt("scale", |v| positive(v, v.f32()?))?.unwrap_or(4.0);
                let colors = match t.get("colors") {
                    Some(v) => {
                        let a = v.array()?;
                        if a.len() != 2 {
                            return Err(v.err(format!("expected an array of 2 colours, found {} elements", a.len())));
                        }
                        let c = |k: usize| Val { doc: v.doc, field: format!("{}[{k}]", v.field), value: &a[k] }.color();
                        [c(0)?, c(1)?]
                    }
                    None => [Rgb::ZERO, Rgb::ONE],
                };
                let octaves = t.opt("octaves", |v| in_range(v, v.integer()?, 1, 16))?.unwrap_or(7) as u32;
                let seed = t.opt("seed", |v| in_range(v, v.integer()?, 0, i64::MAX))?.unwrap_or(0) as u64;
                Texture::Noise(Noise::new(kind, scale, colors, octaves, seed))
            }
            _ => {
                only(&["color"])?;
                Texture::Constant(t.req("color")?.color()?)
            }
        };
        let id = scene.add_texture(name.clone(), tex);
        if srgb {
            self.srgb_textures.insert(id);
        }
        self.texture_ids.insert(name, id);
        Ok(())
    }

    /// A texture holding data rather than colour (`srgb = false`), by name.
    fn data_texture(&self, v: &Val, key: &str, holds: &str) -> Result<TextureId, LoadError> {
        match self.tex_color(v)? {
            TexColor::Texture(id) if self.srgb_textures.contains(&id) => Err(v.err(format!("texture `{}` is decoded from sRGB, but `{key}` {holds}: give it `srgb = false`", v.str()?))),
            TexColor::Texture(id) => Ok(id),
            TexColor::Constant(_) => Err(v.err("must name a texture")),
        }
    }

    /// A colour parameter: a colour, or the name of a texture.
    fn tex_color(&self, v: &Val) -> Result<TexColor, LoadError> {
        if let Ok(name) = v.str() {
            return self.texture_ids.get(name).map(|&id| TexColor::Texture(id)).ok_or_else(|| {
                let mut names: Vec<&str> = self.texture_ids.keys().map(String::as_str).collect();
                names.sort();
                v.err(format!("unknown texture `{name}` (defined: {})", if names.is_empty() { "none".into() } else { names.join(", ") }))
            });
        }
        v.color().map(TexColor::Constant)
    }

    fn material(&mut self, scene: &mut SceneDescription, t: &Table) -> Result<(), LoadError> {
        let name_v = t.req("name")?;
        let name = name_v.str()?.to_string();
        if self.material_ids.contains_key(&name) {
            return Err(name_v.err(format!("a material named `{name}` already exists")));
        }
        let kind = t.type_name(&["diffuse", "phong", "mirror", "dielectric", "cooktorrance", "conductor", "hair", "metallic-roughness"])?;
        let valid: &[&str] = match kind {
            "diffuse" => &["albedo"],
            "phong" => &["ka", "kd", "ks", "exponent"],
            "mirror" => &["reflectance"],
            "cooktorrance" => &["diffuse", "specular", "roughness", "distribution", "geometry", "f0"],
            "conductor" => &["metal", "eta", "k", "roughness", "distribution", "geometry"],
            "hair" => &["color", "kd", "ks", "exponent"],
            "metallic-roughness" => &["base_color", "metallic", "roughness", "metallic_roughness"],
            _ => &["ior"],
        };
        for k in MATERIAL {
            if !MATERIAL_COMMON.contains(k) && !valid.contains(k) && t.has(k) {
                return Err(t.get(k).unwrap().err(format!("not a field of `{kind}` materials (valid: {}, {})", MATERIAL_COMMON.join(", "), valid.join(", "))));
            }
        }
        let color = |key: &str, default: Rgb| -> Result<TexColor, LoadError> { t.get(key).map(|v| self.tex_color(&v)).transpose().map(|c| c.unwrap_or(TexColor::Constant(default))) };
        let roughness = || t.opt("roughness", |v| in_range_f32(v, v.f32()?, 1e-3, 10.0));
        let distribution = || t.opt("distribution", |v| v.str()?.parse::<Distribution>().map_err(|e| v.err(e.to_string())));
        let geometry = || t.opt("geometry", |v| v.str()?.parse::<MicrofacetGeometry>().map_err(|e| v.err(e.to_string())));
        let m = match kind {
            "diffuse" => Material::Diffuse { albedo: color("albedo", Rgb::splat(0.5))? },
            "phong" => Material::Phong {
                ka: color("ka", Rgb::ZERO)?,
                kd: color("kd", Rgb::splat(0.5))?,
                ks: color("ks", Rgb::ZERO)?,
                exponent: t.opt("exponent", |v| {
                    let e = v.f32()?;
                    if e < 0.0 {
                        Err(v.err(format!("must not be negative, found {e}")))
                    } else {
                        Ok(e)
                    }
                })?
                .unwrap_or(32.0),
            },
            "mirror" => Material::Mirror { reflectance: color("reflectance", Rgb::ONE)? },
            "cooktorrance" => Material::CookTorrance {
                diffuse: color("diffuse", Rgb::ZERO)?,
                specular: color("specular", Rgb::ONE)?,
                roughness: roughness()?.unwrap_or(0.2),
                distribution: distribution()?.unwrap_or(Distribution::Ggx),
                geometry: geometry()?.unwrap_or(MicrofacetGeometry::Smith),
                f0: color("f0", Rgb::splat(0.04))?,
            },
            "conductor" => {
                let (eta, k) = self.metal(t)?;
                Material::Conductor { eta, k, roughness: roughness()?.unwrap_or(0.1), distribution: distribution()?.unwrap_or(Distribution::Ggx), geometry: geometry()?.unwrap_or(MicrofacetGeometry::Smith) }
            }
            "hair" => Material::Hair {
                color: color("color", Rgb::new(0.35, 0.2, 0.1))?,
                kd: t.opt("kd", |v| in_range_f32(v, v.f32()?, 0.0, 1.0))?.unwrap_or(0.8),
                ks: t.opt("ks", |v| in_range_f32(v, v.f32()?, 0.0, 1.0))?.unwrap_or(0.2),
                exponent: t.opt("exponent", |v| in_range_f32(v, v.f32()?, 0.0, 10000.0))?.unwrap_or(40.0),
            },
            "metallic-roughness" => Material::MetallicRoughness {
                base_color: color("base_color", Rgb::ONE)?,
                metallic: t.opt("metallic", |v| in_range_f32(v, v.f32()?, 0.0, 1.0))?.unwrap_or(1.0),
                roughness: t.opt("roughness", |v| in_range_f32(v, v.f32()?, 0.0, 1.0))?.unwrap_or(1.0),
                metallic_roughness: t.get("metallic_roughness").map(|v| self.data_texture(&v, "metallic_roughness", "holds metalness and roughness")).transpose()?,
            },
            _ => Material::Dielectric { ior: t.opt("ior", |v| positive(v, v.f32()?))?.unwrap_or(1.5) },
        };
        let perturbation = self.perturbation(t)?;
        let id = scene.add_material(name.clone(), m);
        scene.material_perturbations[id.0 as usize] = perturbation;
        self.material_ids.insert(name, id);
        Ok(())
    }

    /// A conductor's complex index: a named `metal` (default copper) or both `eta` and `k`.
    fn metal(&self, t: &Table) -> Result<(Rgb, Rgb), LoadError> {
        match (t.get("metal"), t.get("eta"), t.get("k")) {
            (Some(_), Some(v), _) | (Some(_), None, Some(v)) => Err(v.err("give either `metal` or `eta` and `k`, not both")),
            (None, Some(ev), Some(kv)) => {
                let eta = ev.color()?;
                if eta.min_element() <= 0.0 {
                    return Err(ev.err(format!("components must be positive, found [{}, {}, {}]", eta.x, eta.y, eta.z)));
                }
                Ok((eta, kv.color()?))
            }
            (None, Some(v), None) | (None, None, Some(v)) => Err(v.err("`eta` and `k` go together: give both")),
            (metal, None, None) => {
                let name = metal.as_ref().map(|v| v.str()).transpose()?.unwrap_or("copper");
                let (_, eta, k) = METALS.iter().find(|(n, ..)| *n == name).ok_or_else(|| {
                    metal.unwrap().err(format!("unknown metal `{name}` (valid: {})", METALS.iter().map(|m| m.0).collect::<Vec<_>>().join(", ")))
                })?;
                Ok((Rgb::from_array(*eta), Rgb::from_array(*k)))
            }
        }
    }

    /// A material's `normal_map` (with `normal_space`) or `bump_map` (with `bump_scale`).
    fn perturbation(&self, t: &Table) -> Result<Option<ShadingPerturbation>, LoadError> {
        let texture = |v: &Val| match self.tex_color(v)? {
            TexColor::Texture(id) => Ok(id),
            TexColor::Constant(_) => Err(v.err("expected the name of a texture")),
        };
        let needs = |key: &str, other: &str| match t.get(key) {
            Some(v) if !t.has(other) => Err(v.err(format!("needs `{other}`"))),
            _ => Ok(()),
        };
        needs("normal_space", "normal_map")?;
        needs("bump_scale", "bump_map")?;
        match (t.get("normal_map"), t.get("bump_map")) {
            (Some(_), Some(b)) => Err(b.err("give either `normal_map` or `bump_map`, not both")),
            (Some(v), None) => {
                let id = texture(&v)?;
                if self.srgb_textures.contains(&id) {
                    return Err(v.err(format!("texture `{}` is decoded from sRGB, but a normal map holds linear vectors: give it `srgb = false`", v.str()?)));
                }
                let space = t.opt("normal_space", |v| v.str()?.parse::<NormalSpace>().map_err(|e| v.err(e)))?.unwrap_or_default();
                Ok(Some(ShadingPerturbation::NormalMap { texture: id, space }))
            }
            (None, Some(v)) => {
                let texture = texture(&v)?;
                // Required: the height is in world units, so no default fits every scene.
                let sv = t.req("bump_scale")?;
                let scale = sv.f32()?;
                if scale == 0.0 {
                    return Err(sv.err("must not be zero"));
                }
                Ok(Some(ShadingPerturbation::Bump { texture, scale }))
            }
            (None, None) => Ok(None),
        }
    }

    fn material_ref(&self, t: &Table) -> Result<Option<MaterialId>, LoadError> {
        let Some(v) = t.get("material") else { return Ok(None) };
        let name = v.str()?;
        self.material_ids.get(name).copied().map(Some).ok_or_else(|| {
            let mut names: Vec<&str> = self.material_ids.keys().map(String::as_str).collect();
            names.sort();
            v.err(format!("unknown material `{name}` (defined: {})", if names.is_empty() { "none".into() } else { names.join(", ") }))
        })
    }

    fn background(&mut self, scene: &mut SceneDescription, t: &Table) -> Result<Background, LoadError> {
        match (t.get("color"), t.get("texture")) {
            (Some(_), Some(v)) => Err(v.err("give either `color` or `texture`, not both")),
            (Some(c), None) => Ok(Background::Color(c.color()?)),
            (None, Some(v)) => {
                let found = self.find(&v)?;
                let tex = self.image_texture(&v, &found, true, Wrap::Repeat, Filter::Bilinear)?;
                Ok(Background::Texture(scene.add_texture(format!("background:{}", v.str()?), Texture::Image(tex))))
            }
            (None, None) => Ok(Background::Color(Rgb::ZERO)),
        }
    }

    fn transform(&self, t: &Table) -> Result<Transform, LoadError> {
        let Some(v) = t.get("transform") else { return Ok(Transform::IDENTITY) };
        let steps = v.array().map_err(|_| v.err("expected an array of steps like [{ scale = 2 }, { translate = [0, 1, 0] }]"))?;
        let mut m = Transform::IDENTITY;
        for (i, step) in steps.iter().enumerate() {
            let sv = Val { doc: self.doc, field: format!("{}[{i}]", v.field), value: step };
            let st = sv.table(TRANSFORM_STEP)?;
            let keys: Vec<&str> = TRANSFORM_STEP.iter().copied().filter(|k| st.has(k)).collect();
            if keys.len() != 1 {
                return Err(sv.err("each step needs exactly one of scale, rotate, translate"));
            }
            let step_t = match keys[0] {
                "scale" => {
                    let s = st.get("scale").unwrap();
                    let f = match s.floats::<3>() {
                        Ok(a) => Vec3::from_array(a),
                        Err(_) => Vec3::splat(s.f32().map_err(|_| s.err("expected a number or an array of 3 numbers"))?),
                    };
                    Transform::scale(f).ok_or_else(|| scale_error(&s, f))?
                }
                "rotate" => {
                    let r = st.get("rotate").unwrap().table(ROTATE)?;
                    let axis = r.req("axis")?;
                    let deg = r.req("degrees")?.f32()?;
                    Transform::rotate(axis.vec3()?, deg).ok_or_else(|| axis.err("the axis must not be zero"))?
                }
                _ => Transform::translate(st.get("translate").unwrap().vec3()?),
            };
            m = m.then(step_t);
        }
        Ok(m)
    }

    fn shape(&mut self, scene: &mut SceneDescription, t: &Table) -> Result<(), LoadError> {
        let kind = t.type_name(&["sphere", "triangle", "quad", "mesh", "curve", "bezier_patch"])?;
        let valid: &[&str] = match kind {
            "sphere" => &["center", "radius"],
            "triangle" => &["vertices", "normals", "uvs"],
            "quad" => &["vertices", "uvs"],
            "curve" => crate::curves::KEYS,
            "bezier_patch" => &["file", "mode", "subdivisions"],
            _ => &["file", "smooth", "crease_angle"],
        };
        for k in SHAPE {
            if !["type", "material", "transform"].contains(k) && !valid.contains(k) && t.has(k) {
                return Err(t.get(k).unwrap().err(format!("not a field of `{kind}` shapes (valid: type, material, transform, {})", valid.join(", "))));
            }
        }
        let material = self.material_ref(t)?;
        let to_world = self.transform(t)?;
        let mat = material.unwrap_or_default();
        match kind {
            "sphere" => {
                let center = t.opt("center", |v| v.vec3())?.unwrap_or(Vec3::ZERO);
                let rv = t.req("radius")?;
                let radius = positive(&rv, rv.f32()?)?;
                scene.geometry.add_sphere(Sphere { center, radius, to_world, material: mat, emission: Rgb::ZERO });
            }
            "triangle" | "quad" => {
                let n = if kind == "triangle" { 3 } else { 4 };
                let vv = t.req("vertices")?;
                let verts = vv.points().map_err(|_| vv.err(format!("expected an array of {n} points [x, y, z]")))?;
                if verts.len() != n {
                    return Err(vv.err(format!("expected {n} vertices, found {}", verts.len())));
                }
                let mut mesh = TriangleMesh { name: kind.into(), positions: verts.iter().map(|&p| to_world.point(p)).collect(), material: mat, object_to_world: to_world, ..Default::default() };
                mesh.indices = if n == 3 { vec![[0, 1, 2]] } else { vec![[0, 1, 2], [0, 2, 3]] };
                if let Some(nv) = t.get("normals") {
                    let normals = nv.points()?;
                    if normals.len() != n || normals.iter().any(|v| v.length_squared() == 0.0) {
                        return Err(nv.err(format!("expected {n} non-zero normals")));
                    }
                    mesh.normals = normals.iter().map(|&v| to_world.normal(v).normalize()).collect();
                }
                match t.get("uvs") {
                    Some(uv) => {
                        let a = uv.array()?;
                        if a.len() != n {
                            return Err(uv.err(format!("expected {n} coordinates [u, v], found {}", a.len())));
                        }
                        mesh.uvs = a.iter().enumerate().map(|(k, e)| Val { doc: self.doc, field: format!("{}[{k}]", uv.field), value: e }.vec2()).collect::<Result<_, _>>()?;
                    }
                    None if n == 4 => mesh.uvs = vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)],
                    None => {}
                }
                scene.geometry.add_mesh(mesh);
            }
            "curve" => {
                let file = t.get("file").map(|fv| self.find(&fv).map(|found| (fv, found))).transpose()?;
                crate::curves::add_curves(scene, t, file, mat, &to_world)?;
            }
            "bezier_patch" => {
                let found = self.find(&t.req("file")?)?;
                let direct = match t.get("mode") {
                    None => false,
                    Some(v) => match v.str()? {
                        "tessellate" => false,
                        "direct" => true,
                        m => return Err(v.err(format!("unknown mode `{m}` (valid: tessellate, direct)"))),
                    },
                };
                if direct {
                    if let Some(v) = t.get("subdivisions") {
                        return Err(v.err("only used with mode = \"tessellate\""));
                    }
                    let patches = load_patches_world(&found, &to_world)?;
                    scene.geometry.add_patches(PatchSurfaces::new(patches, DEFAULT_SEED_GRID, mat));
                } else {
                    let subdivisions = t.opt("subdivisions", |v| in_range(v, v.integer()?, 1, 256))?.map_or(DEFAULT_SUBDIVISIONS, |n| n as u32);
                    let mesh = load_patch_mesh(&found, subdivisions, &to_world)?;
                    scene.geometry.add_mesh(TriangleMesh { material: mat, ..mesh });
                }
            }
            _ => {
                let fv = t.req("file")?;
                crate::mesh_scene::MeshFormat::require(fv.str()?).map_err(|e| fv.err(e))?;
                let found = self.find(&fv)?;
                let smooth = t.opt("smooth", |v| v.bool())?.unwrap_or(false);
                let crease = t.opt("crease_angle", |v| if smooth { in_range_f32(v, v.f32()?, 0.0, 180.0) } else { Err(v.err("needs `smooth = true`")) })?.unwrap_or(180.0);
                let obj = load_mesh_file(&found, &to_world)?;
                scene.warnings.extend(obj.warnings.iter().cloned());
                for (mut mesh, mtl) in obj.meshes {
                    if let Some(ke) = mtl.and_then(|k| obj.materials.get(k)).and_then(|m| m.emissive) {
                        mesh.emission = mtl_color(Some(ke), Rgb::ZERO);
                    }
                    mesh.material = match (material, mtl) {
                        (Some(m), _) => m,
                        (None, Some(k)) if k < obj.materials.len() => self.mtl_material(scene, &fv, &obj.materials, k, obj.mtl_dir.as_ref())?,
                        _ => MaterialId::default(),
                    };
                    if smooth && mesh.normals.is_empty() {
                        mesh.compute_smooth_normals(crease);
                    }
                    mesh.object_to_world = to_world;
                    scene.geometry.add_mesh(mesh);
                }
            }
        }
        Ok(())
    }

    /// Converts an MTL material (once per file and index).
    fn mtl_material(&mut self, scene: &mut SceneDescription, v: &Val, mats: &[MtlMaterial], k: usize, mtl: Option<&Found>) -> Result<MaterialId, LoadError> {
        let key = (mtl.map(|f| f.path().display().to_string()).unwrap_or_default(), k);
        if let Some(&id) = self.mtl_cache.get(&key) {
            return Ok(id);
        }
        let m = &mats[k];
        let kd = match (&m.diffuse_texture, mtl) {
            (Some(file), Some(mtl)) => {
                let found = mtl.sibling_resolver().find(file).map_err(|tried| v.err(format!("map_Kd of material `{}`: {}", m.name, not_found_message(file, &tried))))?;
                let tex = self.image_texture(v, &found, true, Wrap::Repeat, Filter::Bilinear)?;
                TexColor::Texture(scene.add_texture(format!("{}:map_Kd", m.name), Texture::Image(tex)))
            }
            _ => TexColor::Constant(mtl_color(m.diffuse, Rgb::splat(0.5))),
        };
        let ks = mtl_color(m.specular, Rgb::ZERO);
        let illum = m.illumination_model.unwrap_or(2);
        let material = if matches!(illum, 4 | 6 | 7) || m.dissolve.is_some_and(|d| d < 1.0) {
            Material::Dielectric { ior: m.optical_density.filter(|&n| n > 0.0).unwrap_or(1.5) }
        } else if illum == 3 && ks.max_element() > 0.0 {
            Material::Mirror { reflectance: TexColor::Constant(ks) }
        } else if ks.max_element() > 0.0 {
            Material::Phong { ka: TexColor::Constant(mtl_color(m.ambient, Rgb::ZERO)), kd, ks: TexColor::Constant(ks), exponent: m.shininess.unwrap_or(32.0).max(0.0) }
        } else {
            Material::Diffuse { albedo: kd }
        };
        let id = scene.add_material(m.name.clone(), material);
        self.mtl_cache.insert(key, id);
        Ok(id)
    }

    fn light(&mut self, scene: &mut SceneDescription, t: &Table) -> Result<(), LoadError> {
        let kind = t.type_name(&["point", "directional", "ambient", "grid", "rect", "sphere", "environment"])?;
        let valid: &[&str] = match kind {
            "point" => &["position", "intensity"],
            "directional" => &["direction", "irradiance"],
            "grid" => &["vertices", "n", "intensity"],
            "rect" => &["vertices", "radiance", "texture"],
            "sphere" => &["center", "radius", "radiance"],
            "environment" => &["file", "scale"],
            _ => &["intensity"],
        };
        for k in LIGHT {
            if *k != "type" && !valid.contains(k) && t.has(k) {
                return Err(t.get(k).unwrap().err(format!("not a field of `{kind}` lights (valid: type, {})", valid.join(", "))));
            }
        }
        let light = match kind {
            "point" => Light::Point { position: t.req("position")?.vec3()?, intensity: t.req("intensity")?.color()? },
            "directional" => {
                let dv = t.req("direction")?;
                let direction = dv.vec3()?.try_normalize().ok_or_else(|| dv.err("must not be zero"))?;
                Light::Directional { direction, irradiance: t.req("irradiance")?.color()? }
            }
            "ambient" => Light::Ambient { intensity: t.req("intensity")?.color()? },
            "grid" => {
                let [corner, edge_u, edge_v] = self.parallelogram(t)?;
                let nv = t.req("n")?;
                let n = in_range(&nv, nv.integer()?, 1, 64)? as u32;
                Light::Grid { corner, edge_u, edge_v, n, intensity: t.req("intensity")?.color()? }
            }
            "environment" => return self.environment_light(scene, t),
            _ => return self.area_light(scene, kind, t),
        };
        scene.lights.push(light);
        Ok(())
    }

    /// The 4 `vertices` of a light, in order around the boundary, not collinear.
    fn quad_vertices(&self, t: &Table) -> Result<Vec<Vec3>, LoadError> {
        let vv = t.req("vertices")?;
        let verts = vv.points().map_err(|_| vv.err("expected an array of 4 points [x, y, z]"))?;
        if verts.len() != 4 {
            return Err(vv.err(format!("expected 4 vertices, found {}", verts.len())));
        }
        if raylab_core::edges::unit_cross(verts[1] - verts[0], verts[2] - verts[0]).is_none() {
            return Err(vv.err("the first three vertices must not be collinear"));
        }
        Ok(verts)
    }

    /// Corner and edges of the parallelogram spanned by `vertices` 0, 1 and 3.
    fn parallelogram(&self, t: &Table) -> Result<[Vec3; 3], LoadError> {
        let v = self.quad_vertices(t)?;
        Ok([v[0], v[1] - v[0], v[3] - v[0]])
    }

    /// An equirectangular image (PNG, EXR, ...) around the scene, importance sampled; it is
    /// the background too.
    fn environment_light(&mut self, scene: &mut SceneDescription, t: &Table) -> Result<(), LoadError> {
        let tv = t.req("type")?;
        if self.has_background {
            return Err(tv.err("an environment light is the scene's background: remove `[background]`"));
        }
        if scene.environment.is_some() {
            return Err(tv.err("only one environment light is allowed"));
        }
        let scale = t.opt("scale", |v| v.color())?.unwrap_or(Rgb::ONE);
        let fv = t.req("file")?;
        let found = self.find(&fv)?;
        let image = self.image_texture(&fv, &found, true, Wrap::Repeat, Filter::Bilinear)?;
        EnvironmentLight::check_image(&image).map_err(|e| fv.err(format!("{}: {e}", found.path().display())))?;
        scene.environment = Some(EnvironmentLight::new(image, scale));
        Ok(())
    }

    /// Area lights are geometry that emits and reflects nothing (a black material).
    fn area_light(&mut self, scene: &mut SceneDescription, kind: &str, t: &Table) -> Result<(), LoadError> {
        let rv = t.req("radiance")?;
        let radiance = rv.color()?;
        if radiance.min_element() < 0.0 {
            return Err(rv.err(format!("must not be negative, found {radiance}")));
        }
        let black = *self.material_ids.entry("<area light>".into()).or_insert_with(|| scene.add_material("<area light>", Material::Diffuse { albedo: TexColor::Constant(Rgb::ZERO) }));
        if kind == "sphere" {
            let center = t.req("center")?.vec3()?;
            let rv = t.req("radius")?;
            let radius = positive(&rv, rv.f32()?)?;
            scene.geometry.add_sphere(Sphere { center, radius, to_world: Transform::IDENTITY, material: black, emission: radiance });
            return Ok(());
        }
        let verts = self.quad_vertices(t)?;
        // A textured rect (the third report's window) emits `radiance × texture(uv)`.
        let emission_texture = match t.get("texture") {
            Some(v) => match self.tex_color(&v)? {
                TexColor::Texture(id) => Some(id),
                TexColor::Constant(_) => return Err(v.err("expected the name of a texture")),
            },
            None => None,
        };
        let mesh = TriangleMesh {
            name: "rect light".into(),
            positions: verts,
            indices: vec![[0, 1, 2], [0, 2, 3]],
            uvs: vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)],
            material: black,
            emission: radiance,
            emission_texture,
            ..Default::default()
        };
        scene.geometry.add_mesh(mesh);
        Ok(())
    }
}
