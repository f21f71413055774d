//! `raylab inspect`: what a scene contains, and the statistics of its acceleration
//! structure, without rendering.

use anyhow::Result;
use clap::Args;
use raylab_accel::{Accel, AccelStats, Primitives};
use raylab_core::Vec3;
use raylab_render::{Background, Light, Scene};
use serde::Serialize;

use super::scene_args::SceneArgs;

#[derive(Args, Clone, Debug)]
pub struct InspectArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Print JSON instead of text
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct Report {
    scene: String,
    camera: CameraInfo,
    render: RenderInfo,
    counts: Counts,
    meshes: Vec<MeshInfo>,
    materials: Vec<NamedKind>,
    textures: Vec<String>,
    lights: Vec<NamedKind>,
    background: String,
    bounds: [[f32; 3]; 2],
    geometry_bytes: usize,
    /// Texels of image textures (normal maps included), 12 bytes each.
    texture_bytes: usize,
    accel: AccelStats,
}

#[derive(Serialize)]
struct CameraInfo {
    from: [f32; 3],
    at: [f32; 3],
    up: [f32; 3],
    vfov: f32,
    aperture: f32,
    focus_distance: f32,
}

#[derive(Serialize)]
struct RenderInfo {
    width: u32,
    height: u32,
    spp: u32,
    sampler: String,
    max_depth: u32,
    integrator: String,
    accel: String,
    seed: u64,
}

#[derive(Serialize)]
struct Counts {
    shapes: usize,
    primitives: usize,
    triangles: usize,
    spheres: usize,
    meshes: usize,
    /// Strands of directly intersected curves, and their Bézier segments (primitives).
    curves: usize,
    curve_segments: usize,
    /// Bicubic patches intersected directly (one primitive each).
    patches: usize,
    materials: usize,
    textures: usize,
    lights: usize,
    area_light_primitives: usize,
}

#[derive(Serialize)]
struct MeshInfo {
    name: String,
    triangles: usize,
    vertices: usize,
    has_normals: bool,
    has_uvs: bool,
    material: String,
    bounds: [[f32; 3]; 2],
}

#[derive(Serialize)]
struct NamedKind {
    name: String,
    kind: String,
}

fn v3(v: Vec3) -> [f32; 3] {
    v.to_array()
}

fn report(name: String, scene: &Scene) -> Report {
    let g = &scene.geometry;
    let c = &scene.camera;
    let s = &scene.settings;
    let b = g.total_bounds();
    let geometry_bytes = g.meshes.iter().map(|m| m.positions.len() * 12 + m.normals.len() * 12 + m.uvs.len() * 8 + m.tangents.len() * 16 + m.indices.len() * 12).sum::<usize>()
        + g.spheres.len() * std::mem::size_of::<raylab_render::Sphere>()
        + g.curves.iter().map(|c| c.memory_bytes()).sum::<usize>()
        + g.patch_sets.iter().map(|p| p.memory_bytes()).sum::<usize>()
        + g.len() * 8;
    let texture_bytes = scene.textures.iter().map(|t| match t {
        raylab_render::Texture::Image(i) => i.width() as usize * i.height() as usize * std::mem::size_of::<raylab_core::Rgb>(),
        _ => 0,
    }).sum();
    Report {
        scene: name,
        camera: CameraInfo { from: v3(c.from), at: v3(c.at), up: v3(c.up), vfov: c.vfov, aperture: c.aperture, focus_distance: c.focus_distance },
        render: RenderInfo {
            width: s.width,
            height: s.height,
            spp: s.spp,
            sampler: s.sampler.to_string(),
            max_depth: s.max_depth,
            integrator: s.integrator.to_string(),
            accel: s.accel.to_string(),
            seed: s.seed,
        },
        counts: Counts {
            shapes: g.meshes.len() + g.spheres.len() + g.curves.len() + g.patch_sets.len(),
            primitives: g.len(),
            triangles: g.triangle_count(),
            spheres: g.spheres.len(),
            meshes: g.meshes.len(),
            curves: g.curves.len(),
            curve_segments: g.curves.iter().map(|c| c.len()).sum(),
            patches: g.patch_sets.iter().map(|p| p.len()).sum(),
            materials: scene.materials.len(),
            textures: scene.textures.len(),
            lights: scene.lights.len(),
            area_light_primitives: scene.area_lights.len(),
        },
        meshes: g
            .meshes
            .iter()
            .map(|m| {
                let mb = m.bounds();
                MeshInfo {
                    name: m.name.clone(),
                    triangles: m.len(),
                    vertices: m.positions.len(),
                    has_normals: !m.normals.is_empty(),
                    has_uvs: !m.uvs.is_empty(),
                    material: scene.material_names[m.material.0 as usize].clone(),
                    bounds: [v3(mb.min), v3(mb.max)],
                }
            })
            .collect(),
        materials: scene.material_names.iter().zip(&scene.materials).map(|(n, m)| NamedKind { name: n.clone(), kind: m.type_name().into() }).collect(),
        textures: scene.texture_names.clone(),
        lights: scene.lights.iter().enumerate().map(|(i, l)| NamedKind { name: format!("light {i}"), kind: describe_light(l) }).collect(),
        background: match scene.background {
            _ if scene.environment.is_some() => "environment light (importance sampled)".into(),
            Background::Color(c) => format!("colour [{}, {}, {}]", c.x, c.y, c.z),
            Background::Texture(t) => format!("texture {}", scene.texture_names[t.0 as usize]),
        },
        bounds: if b.is_empty() { [[0.0; 3]; 2] } else { [v3(b.min), v3(b.max)] },
        geometry_bytes,
        texture_bytes,
        accel: scene.accel().stats(),
    }
}

fn describe_light(l: &Light) -> String {
    match l {
        Light::Point { position: p, intensity: i } => format!("point at [{}, {}, {}], intensity [{}, {}, {}] W/sr", p.x, p.y, p.z, i.x, i.y, i.z),
        Light::Spot { position: p, direction: d, intensity: i, cos_inner, cos_outer } => format!(
            "spot at [{}, {}, {}] along [{:.3}, {:.3}, {:.3}], cones {:.1}° and {:.1}°, intensity [{}, {}, {}] W/sr",
            p.x, p.y, p.z, d.x, d.y, d.z, cos_inner.acos().to_degrees(), cos_outer.acos().to_degrees(), i.x, i.y, i.z
        ),
        Light::Directional { direction: d, irradiance: e } => format!("directional along [{:.3}, {:.3}, {:.3}], irradiance [{}, {}, {}]", d.x, d.y, d.z, e.x, e.y, e.z),
        Light::Ambient { intensity: i } => format!("ambient [{}, {}, {}]", i.x, i.y, i.z),
        Light::Grid { corner: c, n, intensity: i, .. } => format!("grid of {n}×{n} jittered point lights from [{}, {}, {}], total intensity [{}, {}, {}] W/sr", c.x, c.y, c.z, i.x, i.y, i.z),
    }
}

pub fn run(a: &InspectArgs) -> Result<()> {
    let pool = a.scene.pool()?;
    let scene = pool.install(|| a.scene.load())?;
    scene.accel().validate(&scene.geometry)?;
    let r = report(a.scene.scene_name(), &scene);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
        return Ok(());
    }
    println!("scene       {}", r.scene);
    let c = &r.camera;
    println!("camera      from {:?} at {:?} up {:?}, vfov {}°, aperture {}, focus {}", c.from, c.at, c.up, c.vfov, c.aperture, c.focus_distance);
    let s = &r.render;
    println!("render      {}×{}, {} spp ({}), integrator {}, max depth {}, accel {}, seed {}", s.width, s.height, s.spp, s.sampler, s.integrator, s.max_depth, s.accel, s.seed);
    let n = &r.counts;
    println!(
        "contents    {} shapes: {} meshes ({} triangles), {} spheres, {} curves ({} segments), {} patches; {} materials, {} textures, {} lights, {} emitting primitives",
        n.shapes, n.meshes, n.triangles, n.spheres, n.curves, n.curve_segments, n.patches, n.materials, n.textures, n.lights, n.area_light_primitives
    );
    println!("bounds      {:?} .. {:?}", r.bounds[0], r.bounds[1]);
    println!("memory      geometry {:.1} KiB, textures {:.1} KiB, acceleration structure {:.1} KiB", r.geometry_bytes as f64 / 1024.0, r.texture_bytes as f64 / 1024.0, r.accel.memory_bytes as f64 / 1024.0);
    println!("background  {}", r.background);
    if !r.meshes.is_empty() {
        println!("meshes:");
        for m in &r.meshes {
            let attrs = match (m.has_normals, m.has_uvs) {
                (true, true) => "normals, uvs",
                (true, false) => "normals",
                (false, true) => "uvs",
                _ => "flat",
            };
            println!("  {:<20} {:>9} triangles {:>9} vertices ({attrs}), material {}, bounds {:?} .. {:?}", m.name, m.triangles, m.vertices, m.material, m.bounds[0], m.bounds[1]);
        }
    }
    println!("materials:  {}", r.materials.iter().map(|m| format!("{} ({})", m.name, m.kind)).collect::<Vec<_>>().join(", "));
    if !r.textures.is_empty() {
        println!("textures:   {}", r.textures.join(", "));
    }
    for l in &r.lights {
        println!("{:<11} {}", l.name, l.kind);
    }
    println!("{}", r.accel);
    Ok(())
}
