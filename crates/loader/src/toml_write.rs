//! The TOML front end's writer: a [`SceneDescription`] back to a scene file, with its meshes
//! and curves in files beside it, such that reading the result gives the same description
//! (and so the same image). `raylab gen` writes its procedural descriptions through it.
//!
//! It writes what a description of plain values holds: the camera, the settings the file
//! gave, a colour background, materials of every type with constant parameters, spheres,
//! triangle meshes (a lone triangle or quad inline, any other mesh as an OBJ file), curves
//! (as Bézier strands in a curve file) and point, directional, ambient and grid lights.
//! What would need more files or has no TOML spelling (textures, normal maps, transformed
//! spheres, emitters, Bézier patches, spot and environment lights, build options) is an
//! error naming it, never silently dropped.

use std::fmt::Write;

use raylab_core::{Rgb, Transform, Vec2, Vec3, Vec4};
use raylab_render::material::TexColor;
use raylab_render::settings::{SettingValue, SETTINGS};
use raylab_render::shape::Curve;
use raylab_render::{Background, Light, Material, MaterialId, TriangleMesh};

use crate::description::SceneDescription;

/// A scene file and the files it names, by the names it gives them.
#[derive(Debug)]
pub struct WrittenScene {
    pub toml: String,
    pub side_files: Vec<SideFile>,
}

/// A mesh (OBJ) or curve file the scene names, to be written beside it.
#[derive(Debug)]
pub struct SideFile {
    pub name: String,
    pub contents: String,
}

/// Writes `desc` as a scene file whose side files are named `stem.obj`, `stem-2.obj`, ...
/// and `stem.curves`; `title` heads the file as a comment.
pub fn write_toml(desc: &SceneDescription, stem: &str, title: &str) -> Result<WrittenScene, String> {
    let mut w = Writer { out: String::new(), side_files: Vec::new(), stem, desc };
    w.header(title)?;
    w.materials()?;
    w.shapes()?;
    w.lights()?;
    Ok(WrittenScene { toml: w.out, side_files: w.side_files })
}

struct Writer<'a> {
    out: String,
    side_files: Vec<SideFile>,
    stem: &'a str,
    desc: &'a SceneDescription,
}

/// A float as Rust prints it: the shortest text that reads back to the same `f32`.
fn num(x: f32) -> String {
    format!("{x}")
}

fn vec3(v: Vec3) -> String {
    format!("[{}, {}, {}]", num(v.x), num(v.y), num(v.z))
}

fn vec2(v: Vec2) -> String {
    format!("[{}, {}]", num(v.x), num(v.y))
}

fn points(ps: &[Vec3]) -> String {
    format!("[{}]", ps.iter().map(|&p| vec3(p)).collect::<Vec<_>>().join(", "))
}

/// UVs a `quad` shape gets when it gives none.
const QUAD_UVS: [Vec2; 4] = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];

impl Writer<'_> {
    fn line(&mut self, s: impl AsRef<str>) {
        self.out.push_str(s.as_ref());
        self.out.push('\n');
    }

    fn header(&mut self, title: &str) -> Result<(), String> {
        for l in title.lines() {
            self.line(format!("# {l}"));
        }
        self.line("");
        let c = &self.desc.camera;
        self.line("[camera]");
        self.line(format!("from = {}\nat = {}", vec3(c.from), vec3(c.at)));
        if c.up != Vec3::Y {
            self.line(format!("up = {}", vec3(c.up)));
        }
        self.line(format!("vfov = {}", num(c.vfov)));
        if c.aperture != 0.0 {
            self.line(format!("aperture = {}", num(c.aperture)));
        }
        if let Some(d) = c.focus_distance {
            self.line(format!("focus_distance = {}", num(d)));
        }
        if self.desc.settings.build.is_some() {
            return Err("build options have no scene-file spelling".into());
        }
        let setting = |table: &str| -> Vec<String> {
            SETTINGS
                .iter()
                .filter(|s| s.table == table)
                .filter_map(|s| {
                    self.desc.settings.get(s.key).map(|v| match v {
                        SettingValue::Integer(i) => format!("{} = {i}", s.key),
                        SettingValue::Name(n) => format!("{} = \"{n}\"", s.key),
                    })
                })
                .collect()
        };
        let (camera, render) = (setting("camera"), setting("render"));
        for l in camera {
            self.line(l);
        }
        if !render.is_empty() {
            self.line("\n[render]");
            for l in render {
                self.line(l);
            }
        }
        if self.desc.environment.is_some() {
            return Err("environment lights are read from image files, which the writer does not write".into());
        }
        match self.desc.background {
            Background::Color(c) if c == Rgb::ZERO => {}
            Background::Color(c) => self.line(format!("\n[background]\ncolor = {}", vec3(c))),
            Background::Texture(_) => return Err("a textured background needs its image file, which the writer does not write".into()),
        }
        Ok(())
    }

    fn materials(&mut self) -> Result<(), String> {
        if !self.desc.textures.is_empty() {
            return Err(format!("texture `{}`: textures are not written (they need their image files)", self.desc.texture_names[0]));
        }
        // Material 0 is the implicit default of every scene.
        for (k, m) in self.desc.materials.iter().enumerate().skip(1) {
            let name = &self.desc.material_names[k];
            if self.desc.material_perturbations[k].is_some() {
                return Err(format!("material `{name}`: normal and bump maps need their textures, which the writer does not write"));
            }
            let c = |t: &TexColor| match t {
                TexColor::Constant(c) => Ok(vec3(*c)),
                TexColor::Texture(_) => Err(format!("material `{name}`: textured parameters are not written")),
            };
            let fields = match m {
                Material::Diffuse { albedo } => format!("albedo = {}", c(albedo)?),
                Material::Phong { ka, kd, ks, exponent } => format!("ka = {}\nkd = {}\nks = {}\nexponent = {}", c(ka)?, c(kd)?, c(ks)?, num(*exponent)),
                Material::Mirror { reflectance } => format!("reflectance = {}", c(reflectance)?),
                Material::Dielectric { ior } => format!("ior = {}", num(*ior)),
                Material::CookTorrance { diffuse, specular, roughness, distribution, geometry, f0 } => {
                    format!("diffuse = {}\nspecular = {}\nroughness = {}\ndistribution = \"{distribution}\"\ngeometry = \"{geometry}\"\nf0 = {}", c(diffuse)?, c(specular)?, num(*roughness), c(f0)?)
                }
                Material::Conductor { eta, k, roughness, distribution, geometry } => {
                    format!("eta = {}\nk = {}\nroughness = {}\ndistribution = \"{distribution}\"\ngeometry = \"{geometry}\"", vec3(*eta), vec3(*k), num(*roughness))
                }
                Material::Hair { color, kd, ks, exponent } => format!("color = {}\nkd = {}\nks = {}\nexponent = {}", c(color)?, num(*kd), num(*ks), num(*exponent)),
                Material::MetallicRoughness { base_color, metallic, roughness, metallic_roughness } => {
                    if metallic_roughness.is_some() {
                        return Err(format!("material `{name}`: textured parameters are not written"));
                    }
                    format!("base_color = {}\nmetallic = {}\nroughness = {}", c(base_color)?, num(*metallic), num(*roughness))
                }
            };
            self.line(format!("\n[[materials]]\nname = {name:?}\ntype = \"{}\"\n{fields}", m.type_name()));
        }
        Ok(())
    }

    /// The `material = ...` line of a shape, none for the default material.
    fn material_line(&self, m: MaterialId) -> String {
        if m == MaterialId::default() {
            String::new()
        } else {
            format!("material = {:?}\n", self.desc.material_names[m.0 as usize])
        }
    }

    fn shapes(&mut self) -> Result<(), String> {
        let g = &self.desc.geometry;
        if !g.patch_sets.is_empty() {
            return Err("Bézier patches are not written (their patch files are not kept)".into());
        }
        for s in &g.spheres {
            if s.to_world != Transform::IDENTITY {
                return Err(format!("the sphere at {} has a transform, which the writer does not write", s.center));
            }
            if s.emission != Rgb::ZERO {
                return Err(format!("the sphere at {} emits light: area lights are not written", s.center));
            }
            let m = self.material_line(s.material);
            self.line(format!("\n[[shapes]]\ntype = \"sphere\"\ncenter = {}\nradius = {}\n{m}", vec3(s.center), num(s.radius)).trim_end());
        }
        let mut files = 0;
        for mesh in &g.meshes {
            if mesh.emission != Rgb::ZERO {
                return Err(format!("mesh `{}` emits light: area lights are not written", mesh.name));
            }
            if !mesh.tangents.is_empty() {
                return Err(format!("mesh `{}` has tangents for a normal map, which the writer does not write", mesh.name));
            }
            let m = self.material_line(mesh.material);
            let shape = match inline_shape(mesh) {
                Some(fields) => format!("\n[[shapes]]\n{fields}\n{m}"),
                None => {
                    files += 1;
                    let name = if files == 1 { format!("{}.obj", self.stem) } else { format!("{}-{files}.obj", self.stem) };
                    self.side_files.push(SideFile { name: name.clone(), contents: crate::obj::obj_text(mesh) });
                    format!("\n[[shapes]]\ntype = \"mesh\"\nfile = {name:?}\n{m}")
                }
            };
            self.line(shape.trim_end());
        }
        self.curves()
    }

    /// Every curve as one strand of Bézier control points, each strand's material its shape's:
    /// consecutive curves of one material share a `[[shapes]]` entry and its file.
    fn curves(&mut self) -> Result<(), String> {
        let curves = &self.desc.geometry.curves;
        let mut start = 0;
        let mut files = 0;
        while start < curves.len() {
            let (material, degree) = (curves[start].material, curves[start].segments.first().map_or(3, |s| s.degree()));
            let end = start + curves[start..].iter().take_while(|c| c.material == material && c.segments.iter().all(|s| s.degree() == degree)).count();
            let mut text = String::from("# written by raylab\n");
            for c in &curves[start..end] {
                strand(&mut text, c)?;
            }
            files += 1;
            let name = if files == 1 { format!("{}.curves", self.stem) } else { format!("{}-{files}.curves", self.stem) };
            let m = self.material_line(material);
            self.side_files.push(SideFile { name: name.clone(), contents: text });
            self.line(format!("\n[[shapes]]\ntype = \"curve\"\nfile = {name:?}\nbasis = \"bezier\"\ndegree = {degree}\nmode = \"direct\"\n{m}").trim_end());
            start = end;
        }
        Ok(())
    }

    fn lights(&mut self) -> Result<(), String> {
        for l in &self.desc.lights {
            let fields = match l {
                Light::Point { position, intensity } => format!("type = \"point\"\nposition = {}\nintensity = {}", vec3(*position), vec3(*intensity)),
                Light::Directional { direction, irradiance } => format!("type = \"directional\"\ndirection = {}\nirradiance = {}", vec3(*direction), vec3(*irradiance)),
                Light::Ambient { intensity } => format!("type = \"ambient\"\nintensity = {}", vec3(*intensity)),
                Light::Grid { corner, edge_u, edge_v, n, intensity } => {
                    format!("type = \"grid\"\nvertices = {}\nn = {n}\nintensity = {}", points(&[*corner, *corner + *edge_u, *corner + *edge_u + *edge_v, *corner + *edge_v]), vec3(*intensity))
                }
                Light::Spot { .. } => return Err("spot lights have no scene-file spelling (they come from glTF)".into()),
            };
            self.line(format!("\n[[lights]]\n{fields}"));
        }
        Ok(())
    }
}

/// A one-triangle mesh as a `triangle` shape, a two-triangle mesh that reads back exactly as
/// a `quad` does; `None` for any other mesh (it goes to an OBJ file).
fn inline_shape(mesh: &TriangleMesh) -> Option<String> {
    let p = &mesh.positions;
    if p.len() == 3 && mesh.indices == [[0, 1, 2]] {
        let mut s = format!("type = \"triangle\"\nvertices = {}", points(p));
        if !mesh.normals.is_empty() {
            let _ = write!(s, "\nnormals = {}", points(&mesh.normals));
        }
        if !mesh.uvs.is_empty() {
            let _ = write!(s, "\nuvs = [{}]", mesh.uvs.iter().map(|&u| vec2(u)).collect::<Vec<_>>().join(", "));
        }
        return Some(s);
    }
    (p.len() == 4 && mesh.indices == [[0, 1, 2], [0, 2, 3]] && mesh.normals.is_empty() && mesh.uvs == QUAD_UVS).then(|| format!("type = \"quad\"\nvertices = {}", points(p)))
}

/// One curve as a `strand` of `degree·k + 1` points `x y z radius`: consecutive segments share
/// their end points (as every curve the loader or `raylab gen` makes does).
fn strand(out: &mut String, c: &Curve) -> Result<(), String> {
    let mut pts: Vec<Vec4> = Vec::new();
    for s in &c.segments {
        let cp = s.control_points();
        match pts.last() {
            None => pts.extend_from_slice(cp),
            Some(last) if *last == cp[0] => pts.extend_from_slice(&cp[1..]),
            Some(_) => return Err("a curve whose segments do not join cannot be written as one strand".into()),
        }
    }
    out.push_str("strand\n");
    for p in pts {
        let _ = writeln!(out, "{} {} {} {}", num(p.x), num(p.y), num(p.z), num(p.w));
    }
    Ok(())
}
