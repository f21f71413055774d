//! The pbrt-v4 front end: a subset of pbrt-v4's scene format (the directives, shapes,
//! materials, textures and lights listed in `docs/scene-format.md`) to a
//! [`SceneDescription`]. Anything outside the subset is an error naming the file, the line
//! and the directive — or, when lenient, a warning and a skip.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use raylab_core::{Rgb, Transform, Vec2, Vec3};
use raylab_render::light::EnvironmentLight;
use raylab_render::material::{TexColor, METALS};
use raylab_render::bsdf::{Distribution, Geometry as MicrofacetGeometry};
use raylab_render::shape::Sphere;
use raylab_render::texture::{Checker, CheckerSpace, Filter, ImageTexture, Wrap};
use raylab_render::{Background, IntegratorKind, Light, Material, MaterialId, SamplerKind, Texture, TextureId, TriangleMesh};

use crate::description::{CameraDescription, SceneDescription, Span};
use crate::error::LoadError;
use crate::files::read_text;
use crate::files::{not_found_message, Resolver};

/// The directives of the subset, for messages.
const DIRECTIVES: &str = "LookAt, Camera, Film, Sampler, Integrator, WorldBegin, Identity, Translate, Rotate, Scale, Transform, ConcatTransform, AttributeBegin, AttributeEnd, Include, Import, Shape, Material, MakeNamedMaterial, NamedMaterial, Texture, LightSource, AreaLightSource";

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Word(String),
    Str(String),
    Num(f64),
    Open,
    Close,
}

/// The tokens of one file, each with its line.
fn tokenize(path: &Path, src: &str) -> Result<Vec<(Tok, usize)>, LoadError> {
    let mut out = Vec::new();
    let mut chars = src.char_indices().peekable();
    let mut line = 1;
    while let Some(&(i, c)) = chars.peek() {
        match c {
            '\n' => {
                line += 1;
                chars.next();
            }
            c if c.is_whitespace() => {
                chars.next();
            }
            '#' => {
                while chars.peek().is_some_and(|&(_, c)| c != '\n') {
                    chars.next();
                }
            }
            '[' | ']' => {
                out.push((if c == '[' { Tok::Open } else { Tok::Close }, line));
                chars.next();
            }
            '"' => {
                chars.next();
                let start = line;
                let mut s = String::new();
                loop {
                    match chars.next() {
                        None => return Err(LoadError::new(path, Some(start), "", "unterminated string")),
                        Some((_, '"')) => break,
                        Some((_, '\n')) => return Err(LoadError::new(path, Some(start), "", "unterminated string (strings end on their line)")),
                        Some((_, ch)) => s.push(ch),
                    }
                }
                out.push((Tok::Str(s), start));
            }
            _ => {
                let mut end = i;
                while let Some(&(j, ch)) = chars.peek() {
                    if ch.is_whitespace() || matches!(ch, '[' | ']' | '"' | '#') {
                        break;
                    }
                    end = j + ch.len_utf8();
                    chars.next();
                }
                let word = &src[i..end];
                let tok = if word.starts_with(|ch: char| ch.is_ascii_digit() || ch == '-' || ch == '+' || ch == '.') {
                    Tok::Num(word.parse().map_err(|_| LoadError::new(path, Some(line), "", format!("`{word}` is not a number")))?)
                } else {
                    Tok::Word(word.to_string())
                };
                out.push((tok, line));
            }
        }
    }
    Ok(out)
}

/// One parameter: `"type name" value` or `"type name" [ values ]`.
#[derive(Clone, Debug)]
struct Param {
    ty: String,
    name: String,
    nums: Vec<f64>,
    strs: Vec<String>,
    used: std::cell::Cell<bool>,
}

/// A directive with its arguments, where it was written.
struct Directive {
    name: String,
    line: usize,
    /// Leading positional numbers (`Translate 1 2 3`) and strings (`Shape "sphere"`).
    nums: Vec<f64>,
    strs: Vec<String>,
    params: Vec<Param>,
}

/// Builds the description while walking the directives; the graphics state of pbrt-v4.
struct Parser {
    desc: SceneDescription,
    lenient: bool,
    /// Current transformation matrix (object to world, or world to camera before WorldBegin).
    ctm: Transform,
    /// What the world starts with: a mirror when needed to match pbrt's left-handed camera.
    world_root: Transform,
    camera_ctm: Option<(Transform, Span)>,
    fov: f32,
    stack: Vec<State>,
    state: State,
    named_materials: HashMap<String, MaterialId>,
    textures: HashMap<String, TextureId>,
    /// Files being read, to refuse an `Include` cycle.
    open_files: Vec<PathBuf>,
}

#[derive(Clone)]
struct State {
    ctm: Transform,
    material: MaterialId,
    area_light: Option<Rgb>,
}

impl Param {
    fn f32(&self) -> Option<f32> {
        self.nums.first().map(|&v| v as f32)
    }
}

impl Directive {
    fn span(&self, file: &Path) -> Span {
        Span::new(file, Some(self.line), self.name.clone())
    }

    fn param(&self, name: &str) -> Option<&Param> {
        let p = self.params.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }
}

/// Reads a pbrt-v4 scene (and the files it includes) into a description.
pub fn parse_pbrt(path: &Path, lenient: bool) -> Result<SceneDescription, LoadError> {
    let span = Span::new(path, None, "LookAt");
    let camera = CameraDescription { from: Vec3::ZERO, at: Vec3::Z, up: Vec3::Y, vfov: 90.0, aperture: 0.0, focus_distance: None, at_span: span.clone(), up_span: span };
    let mut p = Parser {
        desc: SceneDescription::new(path, camera),
        lenient,
        ctm: Transform::IDENTITY,
        world_root: Transform::IDENTITY,
        camera_ctm: None,
        fov: 90.0,
        stack: Vec::new(),
        state: State { ctm: Transform::IDENTITY, material: MaterialId(0), area_light: None },
        named_materials: HashMap::new(),
        textures: HashMap::new(),
        open_files: Vec::new(),
    };
    // pbrt's defaults differ from raylab's: a path tracer of depth 5 and 16 samples.
    p.desc.settings.integrator = Some(IntegratorKind::Path);
    p.desc.settings.max_depth = Some(6);
    p.desc.settings.spp = Some(16);
    p.desc.settings.width = Some(1280);
    p.desc.settings.height = Some(720);
    p.file(path)?;
    p.finish_camera()?;
    Ok(p.desc)
}

impl Parser {
    fn file(&mut self, path: &Path) -> Result<(), LoadError> {
        if self.open_files.iter().any(|f| f == path) {
            return Err(LoadError::file(path, "includes itself"));
        }
        let src = read_text(path)?;
        let toks = tokenize(path, &src)?;
        self.open_files.push(path.to_path_buf());
        let mut i = 0;
        while i < toks.len() {
            let (d, next) = directive(path, &toks, i)?;
            i = next;
            self.directive(path, &d)?;
            if let Some(p) = d.params.iter().find(|p| !p.used.get()) {
                self.unsupported(path, &d, &format!("parameter \"{} {}\" is not supported", p.ty, p.name))?;
            }
        }
        self.open_files.pop();
        Ok(())
    }

    /// Outside the subset: an error, or when lenient a warning.
    fn unsupported(&mut self, path: &Path, d: &Directive, what: &str) -> Result<(), LoadError> {
        let e = d.span(path).err(format!("{what} (raylab reads a subset of pbrt-v4; see docs/scene-format.md)"));
        if self.lenient {
            self.desc.warnings.push(format!("{e}; skipped"));
            for p in &d.params {
                p.used.set(true);
            }
            Ok(())
        } else {
            Err(e)
        }
    }

    fn directive(&mut self, path: &Path, d: &Directive) -> Result<(), LoadError> {
        let span = d.span(path);
        let nums = |n: usize| -> Result<Vec<f32>, LoadError> {
            if d.nums.len() != n {
                return Err(span.err(format!("expected {n} numbers, found {}", d.nums.len())));
            }
            Ok(d.nums.iter().map(|&v| v as f32).collect())
        };
        let kind = || d.strs.first().cloned().ok_or_else(|| span.err("expected a type name in quotes"));
        match d.name.as_str() {
            "LookAt" => {
                let v = nums(9)?;
                let (eye, look, up) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]), Vec3::new(v[6], v[7], v[8]));
                // pbrt's LookAt is world -> camera; the camera space is left-handed.
                let dir = (look - eye).try_normalize().ok_or_else(|| span.err("the eye and the look-at point coincide"))?;
                let right = up.try_normalize().map(|u| u.cross(dir)).and_then(Vec3::try_normalize).ok_or_else(|| span.err("`up` is parallel to the viewing direction"))?;
                let new_up = dir.cross(right);
                let cam_to_world = glam::Affine3A::from_cols(right.into(), new_up.into(), dir.into(), eye.into());
                self.concat(Transform::from_affine(cam_to_world.inverse()).expect("orthonormal"));
            }
            "Camera" => {
                if kind()? != "perspective" {
                    return self.unsupported(path, d, &format!("camera \"{}\" is not supported (supported: perspective)", kind()?));
                }
                if let Some(f) = d.param("fov") {
                    self.fov = f.f32().filter(|f| *f > 0.0 && *f < 180.0).ok_or_else(|| span.err("fov must be in (0, 180) degrees"))?;
                }
                self.camera_ctm = Some((self.ctm, span));
            }
            "Film" => {
                if kind()? != "rgb" {
                    return self.unsupported(path, d, &format!("film \"{}\" is not supported (supported: rgb)", kind()?));
                }
                let res = |name: &str| -> Result<Option<u32>, LoadError> { d.param(name).map(|p| p.f32().filter(|v| *v >= 1.0 && *v <= 16384.0).map(|v| v as u32).ok_or_else(|| span.err(format!("{name} must be between 1 and 16384")))).transpose() };
                self.desc.settings.width = res("xresolution")?.or(self.desc.settings.width);
                self.desc.settings.height = res("yresolution")?.or(self.desc.settings.height);
                // The output file is the command line's `-o`.
                d.param("filename");
            }
            "Sampler" => {
                self.desc.settings.sampler = Some(match kind()?.as_str() {
                    "independent" => SamplerKind::Random,
                    "stratified" => SamplerKind::Jittered,
                    "sobol" | "zsobol" | "paddedsobol" | "halton" | "pmj02bn" => SamplerKind::Sobol,
                    k => return self.unsupported(path, d, &format!("sampler \"{k}\" is not supported (supported: independent, stratified, sobol, zsobol, paddedsobol, halton, pmj02bn)")),
                });
                if let Some(n) = d.param("pixelsamples") {
                    let n = n.f32().filter(|v| *v >= 1.0).ok_or_else(|| span.err("pixelsamples must be at least 1"))?;
                    self.desc.settings.spp = Some(n as u32);
                    self.desc.spp_span = Some(span.clone());
                }
                // A stratified sampler's x and y samples make spp = x·y.
                if let (Some(x), Some(y)) = (d.param("xsamples"), d.param("ysamples")) {
                    self.desc.settings.spp = Some((x.f32().unwrap_or(4.0) * y.f32().unwrap_or(4.0)) as u32);
                }
            }
            "Integrator" => {
                match kind()?.as_str() {
                    "path" | "volpath" => self.desc.settings.integrator = Some(IntegratorKind::Path),
                    k => return self.unsupported(path, d, &format!("integrator \"{k}\" is not supported (supported: path, volpath)")),
                }
                // pbrt counts bounces; raylab counts path segments from the camera.
                if let Some(m) = d.param("maxdepth") {
                    let m = m.f32().filter(|v| *v >= 0.0 && *v < 1023.0).ok_or_else(|| span.err("maxdepth must be between 0 and 1022"))?;
                    self.desc.settings.max_depth = Some(m as u32 + 1);
                }
            }
            "WorldBegin" => {
                self.finish_camera()?;
                self.ctm = self.world_root;
            }
            "Identity" => self.ctm = self.world_root,
            "Translate" => {
                let v = nums(3)?;
                self.concat(Transform::translate(Vec3::new(v[0], v[1], v[2])));
            }
            "Scale" => {
                let v = nums(3)?;
                self.concat(Transform::scale(Vec3::new(v[0], v[1], v[2])).ok_or_else(|| span.err("scale must not be zero"))?);
            }
            "Rotate" => {
                let v = nums(4)?;
                self.concat(Transform::rotate(Vec3::new(v[1], v[2], v[3]), v[0]).ok_or_else(|| span.err("the axis must not be zero"))?);
            }
            "Transform" | "ConcatTransform" => {
                let v = if d.nums.len() == 16 { nums(16)? } else { return Err(span.err(format!("expected [ 16 numbers ], found {}", d.nums.len()))) };
                // pbrt lists the matrix column by column (translation last), as glam stores it.
                let m = glam::Mat4::from_cols_array(&v.try_into().unwrap());
                let t = Transform::from_affine(glam::Affine3A::from_mat4(m)).ok_or_else(|| span.err("the matrix is singular"))?;
                if d.name == "Transform" {
                    self.ctm = t.then(self.world_root_if_world());
                } else {
                    self.concat(t);
                }
            }
            "AttributeBegin" => {
                self.state.ctm = self.ctm;
                self.stack.push(self.state.clone());
            }
            "AttributeEnd" => {
                let s = self.stack.pop().ok_or_else(|| span.err("AttributeEnd without AttributeBegin"))?;
                self.ctm = s.ctm;
                self.state = s;
            }
            "Include" | "Import" => {
                let name = kind()?;
                let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
                let found = Resolver::Disk { base }.find(&name).map_err(|tried| span.err(not_found_message(&name, &tried)))?;
                self.file(&found.path())?;
            }
            "Shape" => self.shape(path, d)?,
            "Material" => {
                let m = self.material(path, d, 0)?;
                if let Some(m) = m {
                    self.state.material = self.desc.add_material(format!("{}:{}", path.display(), d.line), m);
                }
            }
            "MakeNamedMaterial" => {
                let name = kind()?;
                let Some(t) = d.param("type") else { return Err(span.err("needs a \"string type\" parameter")) };
                let ty = t.strs.first().cloned().unwrap_or_default();
                let d2 = Directive { name: d.name.clone(), line: d.line, nums: Vec::new(), strs: vec![ty], params: d.params.clone() };
                if let Some(m) = self.material(path, &d2, 0)? {
                    let id = self.desc.add_material(name.clone(), m);
                    self.named_materials.insert(name, id);
                }
                for (a, b) in d.params.iter().zip(&d2.params) {
                    a.used.set(a.used.get() || b.used.get());
                }
            }
            "NamedMaterial" => {
                let name = kind()?;
                self.state.material = *self.named_materials.get(&name).ok_or_else(|| span.err(format!("unknown named material `{name}`")))?;
            }
            "Texture" => self.texture(path, d)?,
            "LightSource" => self.light(path, d)?,
            "AreaLightSource" => {
                if kind()? != "diffuse" {
                    return self.unsupported(path, d, &format!("area light \"{}\" is not supported (supported: diffuse)", kind()?));
                }
                let l = self.rgb(d, "L", Rgb::ONE)? * self.scale(d)?;
                self.state.area_light = Some(l);
            }
            other => return self.unsupported(path, d, &format!("unknown or unsupported directive `{other}` (supported: {DIRECTIVES})")),
        }
        Ok(())
    }

    fn world_root_if_world(&self) -> Transform {
        if self.camera_ctm.is_some() { self.world_root } else { Transform::IDENTITY }
    }

    /// pbrt post-multiplies: the new transform applies first.
    fn concat(&mut self, t: Transform) {
        self.ctm = t.then(self.ctm);
    }

    /// Turns the camera transform into raylab's camera (once, at WorldBegin or the end).
    fn finish_camera(&mut self) -> Result<(), LoadError> {
        let Some((world_to_cam, span)) = self.camera_ctm.clone() else {
            return Err(LoadError::file(&self.desc.file, "no `Camera` directive before `WorldBegin` (raylab needs one)"));
        };
        if self.desc.camera.at_span.line.is_some() {
            return Ok(());
        }
        let c = world_to_cam.inv;
        let from = c.transform_point3(Vec3::ZERO);
        let at = c.transform_point3(Vec3::Z);
        let up = c.transform_vector3(Vec3::Y);
        // pbrt's fov is that of the shorter image side.
        let (w, h) = (self.desc.settings.width.unwrap_or(1) as f32, self.desc.settings.height.unwrap_or(1) as f32);
        let vfov = if h <= w { self.fov } else { 2.0 * ((self.fov.to_radians() / 2.0).tan() * h / w).atan().to_degrees() };
        self.desc.camera = CameraDescription { from, at, up, vfov, aperture: 0.0, focus_distance: None, at_span: span.clone(), up_span: span };
        // A camera space of pbrt's handedness (x = up × forward) sees the world mirrored
        // compared with raylab's (x = forward × up): mirror the world about the camera's
        // vertical plane so that the image is pbrt's.
        if c.matrix3.determinant() > 0.0 {
            let flip = glam::Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0));
            self.world_root = Transform::from_affine(c * flip * c.inverse()).expect("a mirror is invertible");
        }
        Ok(())
    }

    fn scale(&self, d: &Directive) -> Result<f32, LoadError> {
        Ok(d.param("scale").and_then(Param::f32).unwrap_or(1.0))
    }

    fn rgb(&self, d: &Directive, name: &str, default: Rgb) -> Result<Rgb, LoadError> {
        let Some(p) = d.param(name) else { return Ok(default) };
        match (p.ty.as_str(), p.nums.len()) {
            ("rgb", 3) | ("color", 3) => Ok(Rgb::new(p.nums[0] as f32, p.nums[1] as f32, p.nums[2] as f32)),
            ("spectrum" | "float", 1) => Ok(Rgb::splat(p.nums[0] as f32)),
            ("blackbody", 1) => Err(Span::new(&self.desc.file, Some(d.line), d.name.clone()).err(format!("\"blackbody {name}\" is not supported: give \"rgb {name}\""))),
            _ => Err(Span::new(&self.desc.file, Some(d.line), d.name.clone()).err(format!("\"{} {name}\": expected 3 rgb values", p.ty))),
        }
    }

    /// A colour parameter or a texture named by a `"texture NAME"` parameter.
    fn tex_color(&self, path: &Path, d: &Directive, name: &str, default: Rgb) -> Result<TexColor, LoadError> {
        if let Some(p) = d.params.iter().find(|p| p.name == name && p.ty == "texture") {
            p.used.set(true);
            let t = p.strs.first().cloned().unwrap_or_default();
            return self.textures.get(&t).map(|&id| TexColor::Texture(id)).ok_or_else(|| d.span(path).err(format!("unknown texture `{t}`")));
        }
        self.rgb(d, name, default).map(TexColor::Constant)
    }

    fn roughness(&self, d: &Directive) -> f32 {
        let r = d.param("roughness").or_else(|| d.param("uroughness")).and_then(Param::f32).unwrap_or(0.0);
        d.param("vroughness");
        // pbrt-v4 remaps roughness to the microfacet α by √r unless told not to.
        let remap = d.param("remaproughness").is_none_or(|p| p.strs.first().is_none_or(|s| s != "false"));
        (if remap { r.sqrt() } else { r }).max(1e-3)
    }

    fn material(&mut self, path: &Path, d: &Directive, _depth: usize) -> Result<Option<Material>, LoadError> {
        let span = d.span(path);
        let kind = d.strs.first().cloned().ok_or_else(|| span.err("expected a material type in quotes"))?;
        Ok(Some(match kind.as_str() {
            "diffuse" => Material::Diffuse { albedo: self.tex_color(path, d, "reflectance", Rgb::splat(0.5))? },
            "dielectric" => {
                let ior = d.param("eta").and_then(Param::f32).unwrap_or(1.5);
                Material::Dielectric { ior }
            }
            "conductor" => {
                let rough = self.roughness(d);
                let (eta, k) = match (d.param("eta"), d.param("k"), d.param("reflectance")) {
                    (Some(e), Some(k), None) if e.ty == "rgb" && k.ty == "rgb" && e.nums.len() == 3 && k.nums.len() == 3 => {
                        (Rgb::new(e.nums[0] as f32, e.nums[1] as f32, e.nums[2] as f32), Rgb::new(k.nums[0] as f32, k.nums[1] as f32, k.nums[2] as f32))
                    }
                    (Some(e), _, None) if e.ty == "spectrum" && !e.strs.is_empty() => {
                        // Named spectra: "metal-Cu-eta" and the like.
                        let metal = e.strs[0].split('-').nth(1).unwrap_or("");
                        let name = match metal { "Cu" => "copper", "Au" => "gold", "Ag" => "silver", "Al" => "aluminium", other => other };
                        let (_, eta, k) = METALS.iter().find(|(n, ..)| *n == name).ok_or_else(|| span.err(format!("unknown metal spectrum `{}` (valid: metal-Cu-eta, metal-Au-eta, metal-Ag-eta, metal-Al-eta)", e.strs[0])))?;
                        (Rgb::from_array(*eta), Rgb::from_array(*k))
                    }
                    (None, None, None) => {
                        let (_, eta, k) = METALS.iter().find(|(n, ..)| *n == "copper").expect("copper is a metal");
                        (Rgb::from_array(*eta), Rgb::from_array(*k))
                    }
                    _ => return Err(span.err("conductor: give \"rgb eta\" and \"rgb k\", or \"spectrum eta\" \"metal-XX-eta\" (reflectance is not supported)")),
                };
                Material::Conductor { eta, k, roughness: rough, distribution: Distribution::Ggx, geometry: MicrofacetGeometry::Smith }
            }
            "coateddiffuse" => {
                // The closest raylab material: a diffuse base under a dielectric GGX lobe whose
                // Fresnel at normal incidence is that of the coating's index (0.04 for 1.5).
                let diffuse = self.tex_color(path, d, "reflectance", Rgb::splat(0.5))?;
                let eta = d.param("eta").and_then(Param::f32).unwrap_or(1.5);
                d.param("thickness");
                let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
                Material::CookTorrance { diffuse, specular: TexColor::Constant(Rgb::ONE), roughness: self.roughness(d), distribution: Distribution::Ggx, geometry: MicrofacetGeometry::Smith, f0: TexColor::Constant(Rgb::splat(f0)) }
            }
            "interface" => return Ok(None),
            other => {
                self.unsupported(path, d, &format!("material \"{other}\" is not supported (supported: diffuse, conductor, dielectric, coateddiffuse)"))?;
                return Ok(None);
            }
        }))
    }

    fn texture(&mut self, path: &Path, d: &Directive) -> Result<(), LoadError> {
        let span = d.span(path);
        let [name, _ty, class] = d.strs.get(0..3).and_then(|s| <[String; 3]>::try_from(s.to_vec()).ok()).ok_or_else(|| span.err("expected \"name\" \"spectrum\"|\"float\" \"class\""))?;
        let tex = match class.as_str() {
            "imagemap" => {
                let file = d.param("filename").and_then(|p| p.strs.first().cloned()).ok_or_else(|| span.err("imagemap needs \"string filename\""))?;
                let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
                let found = Resolver::Disk { base }.find(&file).map_err(|tried| span.err(not_found_message(&file, &tried)))?;
                let srgb = d.param("encoding").and_then(|p| p.strs.first().cloned()).is_none_or(|e| e == "sRGB");
                let (w, h, texels) = crate::image_io::read_image(&found.path(), srgb).map_err(|e| span.err(e.to_string()))?;
                d.param("filter");
                Texture::Image(ImageTexture::new(w, h, texels, Wrap::Repeat, Filter::Bilinear).map_err(|e| span.err(e.to_string()))?)
            }
            "checkerboard" => {
                let even = self.rgb(d, "tex1", Rgb::ONE)?;
                let odd = self.rgb(d, "tex2", Rgb::ZERO)?;
                let scale = d.param("uscale").and_then(Param::f32).unwrap_or(1.0);
                d.param("vscale");
                // pbrt's checks are 1/uscale wide in uv; raylab's `scale` counts checks per unit uv.
                Texture::Checker(Checker { even, odd, scale, space: CheckerSpace::Uv })
            }
            other => return self.unsupported(path, d, &format!("texture \"{other}\" is not supported (supported: imagemap, checkerboard)")),
        };
        let id = self.desc.add_texture(name.clone(), tex);
        self.textures.insert(name, id);
        Ok(())
    }

    fn light(&mut self, path: &Path, d: &Directive) -> Result<(), LoadError> {
        let span = d.span(path);
        let kind = d.strs.first().cloned().ok_or_else(|| span.err("expected a light type in quotes"))?;
        let scale = self.scale(d)?;
        let point = |name: &str, default: Vec3| -> Vec3 { d.param(name).filter(|p| p.nums.len() == 3).map_or(default, |p| Vec3::new(p.nums[0] as f32, p.nums[1] as f32, p.nums[2] as f32)) };
        match kind.as_str() {
            "point" => {
                let intensity = self.rgb(d, "I", Rgb::ONE)? * scale;
                self.desc.lights.push(Light::Point { position: self.ctm.point(point("from", Vec3::ZERO)), intensity });
            }
            "distant" => {
                let irradiance = self.rgb(d, "L", Rgb::ONE)? * scale;
                // pbrt's light travels from `from` to `to`.
                let dir = self.ctm.vector(point("to", Vec3::Z) - point("from", Vec3::ZERO)).try_normalize().ok_or_else(|| span.err("`from` and `to` coincide"))?;
                self.desc.lights.push(Light::Directional { direction: dir, irradiance });
            }
            "infinite" => match d.param("filename").and_then(|p| p.strs.first().cloned()) {
                Some(file) => {
                    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
                    let found = Resolver::Disk { base }.find(&file).map_err(|tried| span.err(not_found_message(&file, &tried)))?;
                    // 8-bit images are sRGB-encoded, as pbrt-v4 reads them; EXR and PFM linear.
                    let (w, h, texels) = crate::image_io::read_image(&found.path(), true).map_err(|e| span.err(e.to_string()))?;
                    // pbrt-v4's maps are equal-area octahedral squares in the light's space:
                    // resampled into raylab's equirectangular map of the world.
                    if w != h {
                        return Err(span.err(format!("{file}: pbrt-v4 environment maps are equal-area octahedral squares, this image is {w}×{h} (pbrt-v4's `imgtool makeequiarea` converts an equirectangular map)")));
                    }
                    let to_light = self.ctm.inv;
                    let (w, h, texels) = crate::octahedral::to_equirect(w, &texels, |d| to_light.transform_vector3(d));
                    let image = ImageTexture::new(w, h, texels, Wrap::Repeat, Filter::Bilinear).map_err(|e| span.err(e.to_string()))?;
                    EnvironmentLight::check_image(&image).map_err(|e| span.err(format!("{}: {e}", found.path().display())))?;
                    self.desc.environment = Some(EnvironmentLight::new(image, Rgb::splat(scale)));
                }
                None => self.desc.background = Background::Color(self.rgb(d, "L", Rgb::ONE)? * scale),
            },
            other => return self.unsupported(path, d, &format!("light \"{other}\" is not supported (supported: point, distant, infinite)")),
        }
        Ok(())
    }

    fn shape(&mut self, path: &Path, d: &Directive) -> Result<(), LoadError> {
        let span = d.span(path);
        let kind = d.strs.first().cloned().ok_or_else(|| span.err("expected a shape type in quotes"))?;
        let emission = self.state.area_light.unwrap_or(Rgb::ZERO);
        let material = self.state.material;
        let to_world = self.ctm;
        let floats = |name: &str, n: usize| -> Result<Vec<f32>, LoadError> {
            let p = d.param(name).ok_or_else(|| span.err(format!("needs \"{name}\"")))?;
            if p.nums.is_empty() || p.nums.len() % n != 0 {
                return Err(span.err(format!("\"{name}\" needs a multiple of {n} values, found {}", p.nums.len())));
            }
            Ok(p.nums.iter().map(|&v| v as f32).collect())
        };
        let mut mesh = match kind.as_str() {
            "sphere" => {
                let radius = d.param("radius").and_then(Param::f32).unwrap_or(1.0);
                if radius <= 0.0 {
                    return Err(span.err(format!("radius must be positive, found {radius}")));
                }
                self.desc.geometry.add_sphere(Sphere { center: Vec3::ZERO, radius, to_world, material, emission });
                return Ok(());
            }
            "trianglemesh" | "bilinearmesh" => {
                let per = if kind == "trianglemesh" { 3 } else { 4 };
                let p = floats("P", 3)?;
                let positions: Vec<Vec3> = p.chunks_exact(3).map(|c| to_world.point(Vec3::new(c[0], c[1], c[2]))).collect();
                let idx: Vec<u32> = match d.param("indices") {
                    Some(ip) => ip.nums.iter().map(|&v| if v >= 0.0 && (v as usize) < positions.len() { Ok(v as u32) } else { Err(span.err(format!("index {v} out of range ({} vertices)", positions.len()))) }).collect::<Result<_, _>>()?,
                    None if positions.len() == per => (0..per as u32).collect(),
                    None => return Err(span.err("needs \"integer indices\"")),
                };
                if !idx.len().is_multiple_of(per) {
                    return Err(span.err(format!("\"indices\" needs a multiple of {per} values, found {}", idx.len())));
                }
                // A bilinear patch's vertices are p00, p10, p01, p11: two triangles.
                let indices = if per == 3 { idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect() } else { idx.chunks_exact(4).flat_map(|c| [[c[0], c[1], c[3]], [c[0], c[3], c[2]]]).collect() };
                let mut m = TriangleMesh { name: kind.clone(), positions, indices, ..Default::default() };
                if d.params.iter().any(|p| p.name == "N") {
                    let n = floats("N", 3)?;
                    m.normals = n.chunks_exact(3).map(|c| to_world.normal(Vec3::new(c[0], c[1], c[2])).normalize_or_zero()).collect();
                }
                if d.params.iter().any(|p| p.name == "uv") {
                    m.uvs = floats("uv", 2)?.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect();
                }
                m
            }
            "plymesh" => {
                let file = d.param("filename").and_then(|p| p.strs.first().cloned()).ok_or_else(|| span.err("plymesh needs \"string filename\""))?;
                let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
                let found = Resolver::Disk { base }.find(&file).map_err(|tried| span.err(not_found_message(&file, &tried)))?;
                let data = crate::mesh_scene::load_mesh_file(&found, &to_world)?;
                data.meshes.into_iter().next().map(|(m, _)| m).expect("a PLY file is one mesh")
            }
            other => return self.unsupported(path, d, &format!("shape \"{other}\" is not supported (supported: trianglemesh, plymesh, sphere, bilinearmesh)")),
        };
        if mesh.indices.is_empty() {
            return Err(span.err("the shape has no triangles"));
        }
        if mesh.normals.len() != mesh.positions.len() {
            mesh.normals.clear();
        }
        if mesh.uvs.len() != mesh.positions.len() {
            mesh.uvs.clear();
        }
        mesh.material = material;
        mesh.emission = emission;
        mesh.object_to_world = to_world;
        self.desc.geometry.add_mesh(mesh);
        Ok(())
    }
}

/// Reads the directive starting at token `i`; returns it and the index after it.
fn directive(path: &Path, toks: &[(Tok, usize)], mut i: usize) -> Result<(Directive, usize), LoadError> {
    let (tok, line) = &toks[i];
    let Tok::Word(name) = tok else {
        return Err(LoadError::new(path, Some(*line), "", format!("expected a directive, found {}", describe(tok))));
    };
    let mut d = Directive { name: name.clone(), line: *line, nums: Vec::new(), strs: Vec::new(), params: Vec::new() };
    i += 1;
    // Positional arguments: numbers (possibly in brackets, as Transform's) and strings that
    // are not "type name" parameter declarations.
    let mut in_brackets = false;
    while i < toks.len() {
        match &toks[i].0 {
            Tok::Num(v) => d.nums.push(*v),
            Tok::Open if d.params.is_empty() && d.strs.is_empty() => in_brackets = true,
            Tok::Close if in_brackets => in_brackets = false,
            Tok::Str(s) if s.split_whitespace().count() == 2 => break,
            Tok::Str(s) => d.strs.push(s.clone()),
            _ => break,
        }
        i += 1;
    }
    while i < toks.len() {
        let (Tok::Str(decl), pline) = &toks[i] else { break };
        let mut words = decl.split_whitespace();
        let (Some(ty), Some(pname), None) = (words.next(), words.next(), words.next()) else {
            return Err(LoadError::new(path, Some(*pline), name.clone(), format!("expected a parameter \"type name\", found \"{decl}\"")));
        };
        let mut p = Param { ty: ty.to_string(), name: pname.to_string(), nums: Vec::new(), strs: Vec::new(), used: std::cell::Cell::new(false) };
        i += 1;
        let mut push = |t: &Tok| match t {
            Tok::Num(v) => {
                p.nums.push(*v);
                true
            }
            Tok::Str(s) => {
                p.strs.push(s.clone());
                true
            }
            Tok::Word(w) if w == "true" || w == "false" => {
                p.strs.push(w.clone());
                true
            }
            _ => false,
        };
        match toks.get(i).map(|t| &t.0) {
            Some(Tok::Open) => {
                i += 1;
                while i < toks.len() && toks[i].0 != Tok::Close {
                    if !push(&toks[i].0) {
                        return Err(LoadError::new(path, Some(toks[i].1), name.clone(), format!("unexpected {} in the values of \"{decl}\"", describe(&toks[i].0))));
                    }
                    i += 1;
                }
                if i == toks.len() {
                    return Err(LoadError::new(path, Some(*pline), name.clone(), format!("the values of \"{decl}\" have no closing `]`")));
                }
                i += 1;
            }
            Some(t) if push(t) => i += 1,
            _ => return Err(LoadError::new(path, Some(*pline), name.clone(), format!("\"{decl}\" has no value"))),
        }
        d.params.push(p);
    }
    Ok((d, i))
}

fn describe(t: &Tok) -> String {
    match t {
        Tok::Word(w) => format!("`{w}`"),
        Tok::Str(s) => format!("\"{s}\""),
        Tok::Num(v) => format!("the number {v}"),
        Tok::Open => "`[`".into(),
        Tok::Close => "`]`".into(),
    }
}
