//! The Utah teapot from Newell's Bézier patches: the common 6,320-triangle tessellation,
//! the same surface from both file formats, normals that agree with the triangles, and
//! every acceleration structure agreeing with brute force on it; the `bezier_patch` shape.

use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters, Primitives};
use raylab_core::{Aabb, Pcg32, Ray, Vec3};
use raylab_loader::files::{Found, Resolver};
use raylab_loader::patches::load_patches;
use raylab_loader::{load_scene, load_scene_str, Overrides};
use raylab_render::shape::bezier_patch::{tessellate, DEFAULT_SUBDIVISIONS};
use raylab_render::shape::{BezierPatch, PatchSurfaces};
use raylab_render::{Geometry, TriangleMesh};
use raylab_testkit::{self as kit, shared_scenes};

fn teapot(file: &str) -> Vec<BezierPatch> {
    load_patches(&Found::Disk(shared_scenes().join(file))).unwrap_or_else(|e| panic!("{e}"))
}

fn newell_teapot(subdivisions: u32) -> TriangleMesh {
    tessellate(&teapot("teapot_newell_patches.txt"), subdivisions)
}

#[test]
fn default_tessellation_is_the_common_6320_triangle_teapot() {
    if !raylab_testkit::shared_files(&["teapot_newell_patches.txt"]) {
        return;
    }
    let patches = teapot("teapot_newell_patches.txt");
    assert_eq!(patches.len(), 32);
    let mesh = tessellate(&patches, DEFAULT_SUBDIVISIONS);
    // 32 × 10 × 10 × 2 = 6,400, less one triangle per quad on the lid's and the bottom's
    // poles: 8 patches with a collapsed edge of 10 quads.
    assert_eq!(mesh.len(), 6320);
    let b = mesh.bounds();
    assert!((b.min - Vec3::new(-3.0, -2.0, 0.0)).abs().max_element() < 1e-3, "{:?}", b);
    assert!((b.max - Vec3::new(3.4335, 2.0, 3.15)).abs().max_element() < 1e-3, "{:?}", b);
    for (k, n) in mesh.normals.iter().enumerate() {
        assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-5, "vertex {k}: {n}");
    }
    // Coarser and finer grids lose their pole triangles the same way.
    for n in [4, 20] {
        assert_eq!(newell_teapot(n).len() as u32, 32 * n * n * 2 - 8 * n);
    }
}

#[test]
fn txt_and_bpt_give_the_same_tessellation() {
    if !raylab_testkit::shared_files(&["teapot_newell_patches.txt", "teapot.bpt"]) {
        return;
    }
    let (txt, bpt) = (teapot("teapot_newell_patches.txt"), teapot("teapot.bpt"));
    assert_eq!(txt, bpt);
    let (a, b) = (tessellate(&txt, 7), tessellate(&bpt, 7));
    assert_eq!((a.positions, a.normals, a.indices), (b.positions, b.normals, b.indices));
}

#[test]
fn vertex_normals_agree_with_the_triangles() {
    if !raylab_testkit::shared_files(&["teapot_newell_patches.txt"]) {
        return;
    }
    let mesh = newell_teapot(DEFAULT_SUBDIVISIONS);
    let mut disagree = 0;
    for tri in 0..mesh.len() as u32 {
        let face = mesh.winding_normal(tri);
        disagree += mesh.indices[tri as usize].iter().filter(|&&k| face.dot(mesh.normals[k as usize]) <= 0.0).count();
    }
    assert_eq!(disagree, 0, "corners whose patch normal faces away from their triangle");
}

/// Whether a ray from just off the triangle's centre along its winding normal crosses the
/// teapot an even number of times, so escapes: its front faces out.
fn faces_out(g: &Geometry, accel: &AnyAccel, mesh: &TriangleMesh, tri: u32) -> bool {
    let centre = mesh.vertices(tri).iter().sum::<Vec3>() / 3.0;
    let mut ray = Ray::segment(centre, mesh.winding_normal(tri), 1e-4, f32::INFINITY);
    let mut crossings = 0;
    while let Some(h) = accel.intersect(g, &ray, &mut Counters::default()) {
        crossings += 1;
        ray.t_min = h.t + 1e-4;
    }
    crossings % 2 == 0
}

#[test]
fn newell_data_is_oriented_outwards() {
    if !raylab_testkit::shared_files(&["teapot_newell_patches.txt"]) {
        return;
    }
    // The teapot is not closed (the spout and handle pierce the body, the lid sits in the
    // rim), so parity misjudges some triangles near those seams; per patch, the large
    // majority still says whether ∂P/∂u × ∂P/∂v points out.
    let mesh = newell_teapot(DEFAULT_SUBDIVISIONS);
    let mut g = Geometry::default();
    g.add_mesh(mesh.clone());
    let accel = AnyAccel::build(AccelKind::Bvh, &g, &BuildOptions::default());
    let vertices_per_patch = 11 * 11;
    let mut out = [0u32; 32];
    let mut all = [0u32; 32];
    for tri in 0..mesh.len() as u32 {
        let patch = mesh.indices[tri as usize][0] as usize / vertices_per_patch;
        all[patch] += 1;
        out[patch] += faces_out(&g, &accel, &mesh, tri) as u32;
    }
    for p in 0..32 {
        assert!(out[p] as f32 > 0.8 * all[p] as f32, "patch {p}: {} of {} triangles face out", out[p], all[p]);
    }
}

#[test]
fn every_accel_agrees_with_brute_force_on_the_teapot() {
    if !raylab_testkit::shared_files(&["teapot_newell_patches.txt"]) {
        return;
    }
    let mut g = Geometry::default();
    g.add_mesh(newell_teapot(DEFAULT_SUBDIVISIONS));
    let b = g.total_bounds();
    let around = Aabb::new(b.min - b.extent(), b.max + b.extent());
    let rays = kit::random_rays(&mut Pcg32::new(6, 320), 3000, &around, &b);
    let oracle = AnyAccel::build(AccelKind::None, &g, &BuildOptions::default());
    let mut c = Counters::default();
    let want: Vec<_> = rays.iter().map(|r| oracle.intersect(&g, r, &mut c)).collect();
    assert!(want.iter().filter(|h| h.is_some()).count() > 1000, "too few rays hit the teapot");
    for &kind in AccelKind::ALL {
        let accel = AnyAccel::build(kind, &g, &BuildOptions::default());
        accel.validate(&g).unwrap_or_else(|e| panic!("{kind}: {e}"));
        for (k, (ray, want)) in rays.iter().zip(&want).enumerate() {
            match (want, accel.intersect(&g, ray, &mut c)) {
                (None, None) => {}
                (Some(w), Some(h)) => {
                    assert_eq!(h.t, w.t, "{kind} ray {k}: distance");
                    // Equal distances may come from neighbouring triangles (shared edges).
                    if h.prim != w.prim {
                        assert_eq!(g.intersect(h.prim, ray).map(|x| x.t), Some(w.t), "{kind} ray {k}: prim {} vs {}", h.prim, w.prim);
                    }
                }
                (w, h) => panic!("{kind} ray {k}: {h:?} vs brute force {w:?}"),
            }
            assert_eq!(accel.occluded(&g, ray, &mut c), want.is_some(), "{kind} ray {k}: any hit");
        }
    }
}

const CAMERA: &str = "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n";

fn scene_error(shape: &str) -> String {
    let src = format!("{CAMERA}[[shapes]]\ntype = \"bezier_patch\"\n{shape}");
    match load_scene_str(&src, std::path::Path::new("bad.toml"), &Resolver::Disk { base: shared_scenes() }, &Overrides::default()) {
        Ok(_) => panic!("loaded:\n{src}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn example_scene_stands_the_teapot_up() {
    if !raylab_testkit::shared_files(&["teapot_newell_patches.txt"]) {
        return;
    }
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/teapot_patches.toml");
    let scene = load_scene(&path, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
    let teapot = &scene.geometry.meshes[0];
    assert_eq!(teapot.len(), 6320);
    // Rotated −90° about x, Z-up becomes Y-up: the frame of teapot_6320.obj.
    let b = teapot.bounds();
    assert!((b.min - Vec3::new(-3.0, 0.0, -2.0)).abs().max_element() < 1e-3, "{b:?}");
    assert!((b.max - Vec3::new(3.4335, 3.15, 2.0)).abs().max_element() < 1e-3, "{b:?}");
    // Normals went through the rotation too: the lid's pole looks up.
    let top = (0..teapot.positions.len()).max_by(|&i, &j| teapot.positions[i].y.total_cmp(&teapot.positions[j].y)).unwrap();
    assert!((teapot.normals[top] - Vec3::Y).length() < 1e-5, "{}", teapot.normals[top]);
}

#[test]
fn bezier_patch_shape_errors() {
    if !raylab_testkit::shared_files(&["teapot.bpt"]) {
        return;
    }
    assert_eq!(scene_error("file = \"teapot.bpt\"\nsubdivisions = 0\n"), "bad.toml:8: shapes[0].subdivisions: must be between 1 and 256, found 0");
    assert_eq!(scene_error("file = \"teapot.bpt\"\nsmooth = true\n"), "bad.toml:8: shapes[0].smooth: not a field of `bezier_patch` shapes (valid: type, material, transform, file, mode, subdivisions)");
    assert_eq!(scene_error("file = \"teapot.bpt\"\nmode = \"exact\"\n"), "bad.toml:8: shapes[0].mode: unknown mode `exact` (valid: tessellate, direct)");
    assert_eq!(scene_error("file = \"teapot.bpt\"\nmode = \"direct\"\nsubdivisions = 4\n"), "bad.toml:9: shapes[0].subdivisions: only used with mode = \"tessellate\"");
    assert_eq!(scene_error("subdivisions = 4\n"), "bad.toml:5: shapes[0].file: missing (required)");
    let msg = scene_error("file = \"no_such_teapot.bpt\"\n");
    assert!(msg.starts_with("bad.toml:7: shapes[0].file: cannot find `no_such_teapot.bpt` (looked in "), "{msg}");
}

/// Newton on the patches themselves against a 64-subdivision tessellation (chords within
/// about 1e-4 of the surface) on the same rays.
#[test]
fn newton_patches_agree_with_a_fine_tessellation() {
    if !raylab_testkit::shared_files(&["teapot_newell_patches.txt"]) {
        return;
    }
    let patches = teapot("teapot_newell_patches.txt");
    // A 4 × 4 seed grid misses the nearer of two roots on a few grazing rays here
    // (distances off by up to 0.66); 8 × 8 finds them all.
    let surfaces = PatchSurfaces::new(patches.clone(), 8, Default::default());
    let mut fine = Geometry::default();
    fine.add_mesh(tessellate(&patches, 64));
    let b = fine.total_bounds();
    let around = Aabb::new(b.min - b.extent(), b.max + b.extent());
    let rays = kit::random_rays(&mut Pcg32::new(7, 64), 3000, &around, &b);
    let mut c = Counters::default();
    let exact = AnyAccel::build(AccelKind::Bvh, &surfaces, &BuildOptions::default());
    let tess = AnyAccel::build(AccelKind::Bvh, &fine, &BuildOptions::default());
    let (mut mismatches, mut gaps) = (0, Vec::new());
    for ray in &rays {
        match (exact.intersect(&surfaces, ray, &mut c), tess.intersect(&fine, ray, &mut c)) {
            (Some(e), Some(t)) => {
                let p = surfaces.patch(e.prim).point(e.u, e.v);
                assert!((p - ray.at(e.t)).length() < 1e-4, "the hit is not on the patch: {p} vs {}", ray.at(e.t));
                gaps.push((e.t - t.t).abs() * ray.dir.length());
            }
            (None, None) => {}
            _ => mismatches += 1,
        }
    }
    assert!(gaps.len() > 1000, "too few hits: {}", gaps.len());
    // Rays that graze a silhouette may pass the chords and hit the surface, or not.
    assert!(mismatches <= 3, "{mismatches} rays hit only one of the two");
    gaps.sort_by(f32::total_cmp);
    let (median, p99, max) = (gaps[gaps.len() / 2], gaps[gaps.len() * 99 / 100], gaps[gaps.len() - 1]);
    assert!(median < 3e-4 && p99 < 2e-3 && max < 2e-2, "distance gaps: median {median}, 99th percentile {p99}, max {max}");
}

#[test]
fn every_accel_agrees_with_brute_force_on_newton_patches() {
    if !raylab_testkit::shared_files(&["teapot.bpt"]) {
        return;
    }
    let surfaces = PatchSurfaces::new(teapot("teapot.bpt"), 8, Default::default());
    let b = raylab_accel::primitives::total_bounds(&surfaces);
    let rays = kit::random_rays(&mut Pcg32::new(8, 64), 1000, &Aabb::new(b.min - b.extent(), b.max + b.extent()), &b);
    let oracle = AnyAccel::build(AccelKind::None, &surfaces, &BuildOptions::default());
    let mut c = Counters::default();
    let want: Vec<_> = rays.iter().map(|r| oracle.intersect(&surfaces, r, &mut c)).collect();
    for &kind in AccelKind::ALL {
        let accel = AnyAccel::build(kind, &surfaces, &BuildOptions::default());
        accel.validate(&surfaces).unwrap_or_else(|e| panic!("{kind}: {e}"));
        for (k, (ray, want)) in rays.iter().zip(&want).enumerate() {
            let got = accel.intersect(&surfaces, ray, &mut c);
            assert_eq!(got.map(|h| h.t), want.map(|h| h.t), "{kind} ray {k}");
        }
    }
}

/// The direct patches in a scene render like the tessellation they converge to: the image
/// error against them falls more than tenfold from 4 to 40 subdivisions (what is left at
/// 40 is silhouette pixels at one sample each).
#[test]
fn direct_patches_render_like_fine_tessellations() {
    if !raylab_testkit::shared_files(&["teapot_newell_patches.txt"]) {
        return;
    }
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let o = Overrides { width: Some(80), height: Some(60), spp: Some(1), ..Default::default() };
    let render = |scene: raylab_render::Scene| raylab_render::render(&scene, &|_| {}).pixels;
    let direct = load_scene(&root.join("lab/teapot_patches_direct.toml"), &o).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(direct.geometry.patch_sets[0].len(), 32);
    let direct = render(direct);
    let src = std::fs::read_to_string(root.join("teapot_patches.toml")).unwrap();
    let mse = |n: u32| {
        let text = src.replace("subdivisions = 10", &format!("subdivisions = {n}"));
        let scene = load_scene_str(&text, &root.join("tessellated.toml"), &Resolver::Disk { base: root.clone() }, &o).unwrap_or_else(|e| panic!("{e}"));
        let img = render(scene);
        img.iter().zip(&direct).map(|(a, b)| (*a - *b).length_squared() as f64 / 3.0).sum::<f64>() / img.len() as f64
    };
    let (coarse, fine) = (mse(4), mse(40));
    assert!(fine < 5e-4 && fine * 10.0 < coarse, "MSE against direct: 4 subdivisions {coarse}, 40 subdivisions {fine}");
}
