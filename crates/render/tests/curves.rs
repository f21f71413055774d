//! Curves against the rest of the renderer: every acceleration structure finds the same
//! curve hits as the brute-force oracle, direct intersection agrees with a very fine
//! tessellation, and rays leaving a curve do not hit it again.

use glam::Vec4;
use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters, Primitives};
use raylab_core::{sampling, Pcg32, Ray, Rgb, Vec3};
use raylab_render::shape::curve::{tessellate, to_bezier_segments, Basis, Bezier};
use raylab_render::shape::{Curve, PrimRef};
use raylab_render::{Camera, Geometry, IntegratorKind, Light, Material, MaterialId, RenderSettings, Scene};

fn random_point(rng: &mut Pcg32, half: f32) -> Vec3 {
    Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 * half - Vec3::splat(half)
}

/// A wavy strand of `n` cubic Catmull–Rom segments from a random root, tapering.
fn random_strand(rng: &mut Pcg32, n: usize, length: f32, radius: f32) -> Vec<Bezier> {
    let mut p = random_point(rng, 0.8);
    let mut dir = sampling::uniform_sphere(rng.next_vec2());
    let step = length / n as f32;
    let points: Vec<Vec4> = (0..n + 3).map(|k| {
        let taper = 1.0 - 0.7 * k as f32 / (n + 2) as f32;
        let q = p.extend(radius * taper);
        dir = (dir + 0.8 * sampling::uniform_sphere(rng.next_vec2())).normalize();
        p += step * dir;
        q
    }).collect();
    to_bezier_segments(Basis::CatmullRom, 3, &points).unwrap()
}

fn curve_geometry(rng: &mut Pcg32, strands: usize) -> Geometry {
    let mut g = Geometry::default();
    for _ in 0..strands {
        let n = 1 + rng.below(4) as usize;
        let radius = 0.01 + 0.04 * rng.next_f32();
        g.add_curve(Curve::new(random_strand(rng, n, 0.6, radius), MaterialId::default()));
    }
    g
}

/// Rays from around the box (`outside`: from a sphere around every strand), half aimed at
/// points near a random curve, half anywhere.
fn rays_at(rng: &mut Pcg32, g: &Geometry, n: usize, outside: bool) -> Vec<Ray> {
    (0..n).map(|k| {
        let origin = if outside { 3.0 * sampling::uniform_sphere(rng.next_vec2()) } else { random_point(rng, 2.0) };
        let target = if k % 2 == 0 {
            let c = &g.curves[rng.below(g.curves.len() as u32) as usize];
            let s = &c.segments[rng.below(c.len() as u32) as usize];
            let u = rng.next_f32();
            s.point(u) + 1.5 * s.radius(u) * sampling::uniform_sphere(rng.next_vec2())
        } else {
            random_point(rng, 1.0)
        };
        Ray::new(origin, target - origin)
    }).collect()
}

#[test]
fn every_structure_agrees_with_the_oracle_on_curves() {
    let mut rng = Pcg32::new(11, 3);
    let g = curve_geometry(&mut rng, 300);
    let rays = rays_at(&mut rng, &g, 1500, false);
    let oracle = AnyAccel::build(AccelKind::None, &g, &BuildOptions::default());
    let mut c = Counters::default();
    let hits = rays.iter().filter(|r| oracle.intersect(&g, r, &mut c).is_some()).count();
    assert!(hits > 500, "only {hits} of {} rays hit a curve", rays.len());
    for &kind in AccelKind::ALL {
        let accel = AnyAccel::build(kind, &g, &BuildOptions::default());
        accel.validate(&g).unwrap_or_else(|e| panic!("{kind}: {e}"));
        for (k, ray) in rays.iter().enumerate() {
            let want = oracle.intersect(&g, ray, &mut c);
            let got = accel.intersect(&g, ray, &mut c);
            assert_eq!(got.map(|h| h.t), want.map(|h| h.t), "{kind} ray {k}");
            // Consecutive segments share the sphere at their joint: either may report it.
            if let (Some(w), Some(h)) = (want, got) {
                if w.prim != h.prim {
                    assert_eq!(g.intersect(h.prim, ray).map(|x| x.t), Some(w.t), "{kind} ray {k}: prim {} vs {}", h.prim, w.prim);
                }
            }
            assert_eq!(accel.occluded(&g, ray, &mut c), want.is_some(), "{kind} ray {k}: any hit");
            let short = Ray { t_max: want.map_or(1.0, |h| h.t * 0.5), ..*ray };
            assert_eq!(accel.occluded(&g, &short, &mut c), oracle.occluded(&g, &short, &mut c), "{kind} ray {k}: short any hit");
        }
    }
}

#[test]
fn direct_hits_agree_with_a_fine_tessellation() {
    let mut rng = Pcg32::new(5, 9);
    for strand in 0..6 {
        let segments = random_strand(&mut rng, 3, 1.2, 0.05);
        let mut direct = Geometry::default();
        direct.add_curve(Curve::new(segments.clone(), MaterialId::default()));
        let mut mesh = Geometry::default();
        mesh.add_mesh(tessellate(&segments, 128, 96, MaterialId::default()));
        let (da, ma) = (AnyAccel::build(AccelKind::Bvh, &direct, &BuildOptions::default()), AnyAccel::build(AccelKind::Bvh, &mesh, &BuildOptions::default()));
        let mut c = Counters::default();
        let (mut compared, mut total_error) = (0, 0.0);
        for k in 0..300 {
            // Aim inside the silhouette (at most 0.8 r off the axis, across the view),
            // so that the hits are not grazing.
            let s = &segments[rng.below(3) as usize];
            let u = rng.next_f32();
            let (p, r) = (s.point(u), s.radius(u));
            let origin = p + 3.0 * sampling::uniform_sphere(rng.next_vec2());
            let view = (p - origin).normalize();
            let side = s.derivative(u).truncate().cross(view).normalize();
            let ray = Ray::new(origin, p + side * (0.8 * r * (2.0 * rng.next_f32() - 1.0)) - origin);
            let (Some(hd), Some(hm)) = (da.intersect(&direct, &ray, &mut c), ma.intersect(&mesh, &ray, &mut c)) else {
                panic!("strand {strand} ray {k}: direct {:?}, tessellated {:?}", da.intersect(&direct, &ray, &mut c), ma.intersect(&mesh, &ray, &mut c));
            };
            compared += 1;
            // Direct leaves are flat to 2% of the radius, seen at up to 53° here.
            let error = (hd.t - hm.t).abs() * ray.dir.length() / r;
            assert!(error < 0.1, "strand {strand} ray {k}: t {} vs {} (r = {r})", hd.t, hm.t);
            total_error += error;
            let (gd, gm) = (direct.surface(&ray, hd.prim, hd.t, hd.u, hd.v), mesh.surface(&ray, hm.prim, hm.t, hm.u, hm.v));
            assert!(gd.ns.dot(gm.ns) > 0.98, "strand {strand} ray {k}: normals {} vs {}", gd.ns, gm.ns);
            assert!(gd.ng.dot(-ray.dir) > 0.0, "strand {strand} ray {k}: the normal faces away from the viewer");
        }
        assert!(compared > 250, "strand {strand}: only {compared} rays compared");
        assert!(total_error / (compared as f32) < 0.01, "strand {strand}: mean |Δt| = {} r", total_error / compared as f32);
    }
}

#[test]
fn rays_leaving_a_curve_do_not_hit_it_again() {
    let mut rng = Pcg32::new(77, 1);
    let g = curve_geometry(&mut rng, 60);
    let camera = Camera::new(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 45.0, 1.0, 0.0, None).unwrap();
    let mut scene = Scene::new(camera, RenderSettings::default());
    scene.geometry = g;
    scene.build_accel(&BuildOptions::default());
    // Rays start outside the strands (rays from inside: the capsule test below).
    let rays = rays_at(&mut rng, &scene.geometry, 4000, true);
    let mut c = Counters::default();
    let mut tested = 0;
    for (k, ray) in rays.iter().enumerate() {
        let Some(hit) = scene.intersect(ray, &mut c) else { continue };
        let PrimRef::Curve { curve, seg } = scene.geometry.prim(hit.prim) else { unreachable!() };
        let r = scene.geometry.curves[curve as usize].segments[seg as usize].max_radius();
        for _ in 0..8 {
            // Directions at least 0.2 above the tangent plane: grazing ones may hit the
            // concave inner side of a bend legitimately, very close.
            let dir = raylab_core::Frame::from_z(hit.geom.ng).to_world(sampling::cosine_hemisphere(rng.next_vec2()));
            if dir.dot(hit.geom.ng) < 0.2 {
                continue;
            }
            let out = hit.spawn(dir);
            if let Some(again) = scene.intersect(&out, &mut c) {
                assert!(again.t > 0.1 * r || again.prim != hit.prim, "ray {k}: re-hit prim {} at t = {} (r = {r})", hit.prim, again.t);
            }
            tested += 1;
        }
    }
    assert!(tested > 3000, "{tested}");
}

/// The second report's comparison in small: a few hair strands rendered with direct
/// curves and with tubes of 16 and 4 sides, under Whitted and path tracing.
fn hair_render(mode: Option<u32>, integrator: IntegratorKind) -> Vec<Rgb> {
    let mut rng = Pcg32::new(3, 3);
    let camera = Camera::new(Vec3::new(0.0, 0.0, 3.5), Vec3::ZERO, Vec3::Y, 40.0, 4.0 / 3.0, 0.0, None).unwrap();
    let settings = RenderSettings { width: 96, height: 72, spp: 4, integrator, max_depth: 4, ..Default::default() };
    let mut scene = Scene::new(camera, settings);
    let hair = scene.add_material("hair", Material::Hair { color: Rgb::new(0.5, 0.3, 0.1).into(), kd: 0.7, ks: 0.3, exponent: 40.0 });
    for _ in 0..8 {
        let strand = random_strand(&mut rng, 3, 1.2, 0.08);
        match mode {
            None => scene.geometry.add_curve(Curve::new(strand, hair)),
            Some(sides) => scene.geometry.add_mesh(tessellate(&strand, 16, sides, hair)),
        }
    }
    scene.lights.push(Light::Point { position: Vec3::new(2.0, 3.0, 4.0), intensity: Rgb::splat(60.0) });
    scene.build_accel(&BuildOptions::default());
    let out = raylab_render::render(&scene, &|_| {});
    assert_eq!(out.nonfinite_samples, 0);
    out.pixels
}

#[test]
fn sixteen_sided_tubes_render_like_direct_curves() {
    let mse = |a: &[Rgb], b: &[Rgb]| a.iter().zip(b).map(|(x, y)| (*x - *y).length_squared() as f64 / 3.0).sum::<f64>() / a.len() as f64;
    for integrator in [IntegratorKind::Whitted, IntegratorKind::Path] {
        let direct = hair_render(None, integrator);
        let mean = direct.iter().map(|p| p.length() as f64).sum::<f64>() / direct.len() as f64;
        assert!(mean > 0.005, "{integrator}: the hair is black ({mean})");
        let (tube16, tube4) = (mse(&hair_render(Some(16), integrator), &direct), mse(&hair_render(Some(4), integrator), &direct));
        // Measured: 1.0e-6 and 1.6e-6 for 16 sides, 6e-5 for 4 (mean radiance 0.0086).
        assert!(tube16 < 1e-5 && tube16 < 0.1 * tube4, "{integrator}: MSE of tube16 {tube16}, of tube4 {tube4}");
    }
}

/// A straight strand of three cubic segments from x = -1.5 to 1.5 times `scale`, radius a
/// fifth of `scale`: a capsule, whose surface is where the distance to the axis segment
/// is the radius. Its joints and round ends are where interior pieces can be hit.
fn capsule(scale: f32) -> (Scene, f32) {
    let r = 0.2 * scale;
    let seg = |x0: f32| Bezier::new(&(0..4).map(|k| Vec4::new((x0 + k as f32 / 3.0) * scale, 0.0, 0.0, r)).collect::<Vec<_>>()).unwrap();
    let camera = Camera::new(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 45.0, 1.0, 0.0, None).unwrap();
    let mut scene = Scene::new(camera, RenderSettings::default());
    scene.geometry.add_curve(Curve::new(vec![seg(-1.5), seg(-0.5), seg(0.5)], MaterialId::default()));
    scene.build_accel(&BuildOptions::default());
    (scene, r)
}

/// How far the hit of `ray` at `t` lies outside (+) or inside (-) the capsule's surface,
/// relative to its radius (in f64, so that only the error of `t` counts).
fn capsule_depth(ray: &Ray, t: f32, scale: f32, r: f32) -> f64 {
    let p = ray.origin.as_dvec3() + t as f64 * ray.dir.as_dvec3();
    let x = p.x.clamp(-1.5 * scale as f64, 1.5 * scale as f64);
    ((p - glam::DVec3::new(x, 0.0, 0.0)).length() - r as f64) / r as f64
}

#[test]
fn rays_from_inside_a_strand_find_its_surface_not_its_joints() {
    for scale in [1e-4f32, 1.0, 1e4] {
        let (scene, r) = capsule(scale);
        let mut rng = Pcg32::new(12, scale.to_bits() as u64);
        let mut c = Counters::default();
        // From anywhere inside (near the joints at x = ±0.5 and the ends half the time),
        // in every direction: the exit, on the surface. Before the tube was a union, the
        // interior halves of joint and end spheres were hit first.
        for k in 0..2000 {
            let x = if k % 2 == 0 { [-1.5f32, -0.5, 0.5, 1.5][k / 2 % 4] + 0.3 * (rng.next_f32() - 0.5) } else { 3.0 * rng.next_f32() - 1.5 };
            let x = x.clamp(-1.5, 1.5);
            let origin = Vec3::new(x * scale, 0.0, 0.0) + 0.9 * r * rng.next_f32() * sampling::uniform_sphere(rng.next_vec2());
            let ray = Ray::new(origin, sampling::uniform_sphere(rng.next_vec2()));
            let hit = scene.intersect(&ray, &mut c).unwrap_or_else(|| panic!("scale {scale} ray {k}: leaked out of the strand"));
            let depth = capsule_depth(&ray, hit.t, scale, r);
            assert!(depth.abs() < 1e-4, "scale {scale} ray {k} from {origin}: hit {depth} r off the surface (prim {})", hit.prim);
        }
        // Spawned inwards from hits near the joints and ends, as the renderer spawns them:
        // the far side, never an interior piece just below the origin.
        let mut tested = 0;
        while tested < 2000 {
            let x = [-1.5, -0.5, 0.5, 1.5][tested % 4] + 0.1 * (rng.next_f32() - 0.5);
            let from = 3.0 * scale * sampling::uniform_sphere(rng.next_vec2());
            let Some(hit) = scene.intersect(&Ray::new(from, Vec3::new(x * scale, 0.0, 0.0) - from), &mut c) else { continue };
            let dir = raylab_core::Frame::from_z(-hit.geom.ng).to_world(sampling::cosine_hemisphere(rng.next_vec2()));
            let ray = hit.spawn(dir);
            let again = scene.intersect(&ray, &mut c).unwrap_or_else(|| panic!("scale {scale} spawned ray {tested}: leaked out"));
            let depth = capsule_depth(&ray, again.t, scale, r);
            assert!(depth.abs() < 1e-4, "scale {scale} spawned ray {tested}: re-hit {depth} r off the surface at t = {} (prim {})", again.t, again.prim);
            tested += 1;
        }
    }
}
