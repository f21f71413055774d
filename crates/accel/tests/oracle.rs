//! Every structure against the brute-force oracle, on the same seeded rays: the same
//! primitive and distance for closest hits, the same answer for any-hit queries.

use proptest::prelude::*;
use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters, Primitives, PACKET};
use raylab_core::{Aabb, Pcg32, Ray, Vec3};
use raylab_testkit::{self as kit, Prim, Soup};

fn check_all(name: &str, soup: &Soup, rays: &[Ray]) {
    let oracle = AnyAccel::build(AccelKind::None, soup, &BuildOptions::default());
    for &kind in AccelKind::ALL {
        let accel = AnyAccel::build(kind, soup, &BuildOptions::default());
        accel.validate(soup).unwrap_or_else(|e| panic!("{name}/{kind}: {e}"));
        let mut c = Counters::default();
        for (k, ray) in rays.iter().enumerate() {
            let want = oracle.intersect(soup, ray, &mut c);
            let got = accel.intersect(soup, ray, &mut c);
            // Ties (shared edges, overlapping coplanar faces) may resolve to another primitive
            // at most `kit::ORACLE_ULPS` behind; see `kit::agrees_with_oracle`.
            kit::agrees_with_oracle(soup, ray, want, got).unwrap_or_else(|e| panic!("{name}/{kind} ray {k}: {e}"));
            assert_eq!(accel.occluded(soup, ray, &mut c), want.is_some(), "{name}/{kind} ray {k}: any hit");
            let short = Ray { t_max: want.map_or(1.0, |h| h.t * 0.5), ..*ray };
            assert_eq!(accel.occluded(soup, &short, &mut c), oracle.occluded(soup, &short, &mut c), "{name}/{kind} ray {k}: short any hit");
        }
        check_packets(name, kind, &accel, soup, rays);
    }
}

/// Packets of 16 consecutive rays (and a shorter last one) give exactly the single-ray
/// answers, which the loop above checked against the oracle.
fn check_packets(name: &str, kind: AccelKind, accel: &AnyAccel, soup: &Soup, rays: &[Ray]) {
    for (p, packet) in rays.chunks(PACKET).enumerate() {
        let mut out = vec![None; packet.len()];
        accel.intersect_packet(soup, packet, &mut out);
        for (i, ray) in packet.iter().enumerate() {
            assert_eq!(out[i], accel.intersect_fast(soup, ray), "{name}/{kind} packet {p} ray {i}");
        }
    }
}

fn unit() -> Aabb {
    Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
}

#[test]
fn random_triangle_soups() {
    let mut rng = Pcg32::new(7, 1);
    for n in [1, 2, 3, 10, 100, 2000] {
        let soup = kit::random_triangles(&mut rng, n, &unit(), 0.2);
        let rays = kit::random_rays(&mut rng, 500, &Aabb::new(Vec3::splat(-2.0), Vec3::splat(2.0)), &unit());
        check_all(&format!("soup{n}"), &soup, &rays);
    }
}

#[test]
fn spheres_and_triangles_mixed() {
    let mut rng = Pcg32::new(8, 1);
    let mut soup = kit::random_spheres(&mut rng, 300, &unit(), 0.1);
    soup.push_object(kit::random_triangles(&mut rng, 300, &unit(), 0.1));
    soup.push_object(kit::cube());
    let rays = kit::random_rays(&mut rng, 1000, &unit(), &unit());
    check_all("mixed", &soup, &rays);
}

#[test]
fn degenerate_inputs() {
    let mut rng = Pcg32::new(9, 1);
    let rays = kit::random_rays(&mut rng, 300, &unit(), &unit());
    check_all("empty", &Soup::default(), &rays);
    let p = Vec3::new(0.1, 0.2, 0.3);
    let same: Vec<[Vec3; 3]> = (0..50).map(|k| [p, p + Vec3::X * 0.1 * k as f32, p + Vec3::Y * 0.1]).collect();
    check_all("equal centroids", &Soup::new(vec![Prim::Sphere { center: p, radius: 0.3 }; 40]), &rays);
    check_all("fan", &Soup::triangles(same), &rays);
    let flat: Vec<[Vec3; 3]> = (0..100).map(|k| {
        let x = k as f32 * 0.02 - 1.0;
        [Vec3::new(x, 0.0, -1.0), Vec3::new(x + 0.02, 0.0, -1.0), Vec3::new(x, 0.0, 1.0)]
    }).collect();
    check_all("flat", &Soup::triangles(flat), &rays);
    let zero_area: Vec<[Vec3; 3]> = (0..20).map(|k| [Vec3::splat(k as f32 * 0.05); 3]).collect();
    check_all("zero area", &Soup::triangles(zero_area), &rays);
    for scale in [1e-4f32, 1e4] {
        let b = Aabb::new(Vec3::splat(-scale), Vec3::splat(scale));
        let soup = kit::random_triangles(&mut rng, 500, &b, 0.1 * scale);
        let rays = kit::random_rays(&mut rng, 300, &b, &b);
        check_all(&format!("scale {scale}"), &soup, &rays);
    }
}

#[test]
fn cube_axis_rays_through_edges_and_vertices() {
    let soup = kit::cube();
    let mut rays = Vec::new();
    for &x in &[-0.5f32, -0.25, 0.0, 0.5] {
        for &y in &[-0.5f32, 0.0, 0.5] {
            rays.push(Ray::new(Vec3::new(x, y, -3.0), Vec3::Z));
            rays.push(Ray::new(Vec3::new(-3.0, x, y), Vec3::X));
            rays.push(Ray::new(Vec3::new(x, 3.0, y), -Vec3::Y));
            rays.push(Ray::new(Vec3::new(x * 0.5, y * 0.5, 0.0), Vec3::new(x, y, 1.0).normalize()));
        }
    }
    check_all("cube", &soup, &rays);
}

#[test]
fn stanford_bunny() {
    let path = kit::asset("bunny_4968.obj");
    let soup = kit::read_obj_triangles(&path);
    assert_eq!(soup.len(), 4968);
    let b = soup.bounds();
    let mut rng = Pcg32::new(10, 1);
    let outer = Aabb::new(b.min - b.extent(), b.max + b.extent());
    let rays = kit::random_rays(&mut rng, 2000, &outer, &b);
    check_all("bunny", &soup, &rays);
}

/// Every structure does work on the bunny (non-zero counters of its kind), reports sane
/// statistics, and a BVH tests far fewer primitives per ray than brute force.
#[test]
fn counters_and_stats_on_bunny() {
    let soup = kit::read_obj_triangles(&kit::asset("bunny_4968.obj"));
    let b = soup.bounds();
    let mut rng = Pcg32::new(11, 1);
    let rays = kit::random_rays(&mut rng, 500, &Aabb::new(b.min - b.extent(), b.max + b.extent()), &b);
    let mut per_ray = Vec::new();
    for &kind in AccelKind::ALL {
        let accel = AnyAccel::build(kind, &soup, &BuildOptions::default());
        let s = accel.stats();
        println!("{s}");
        assert_eq!(s.primitives, soup.len(), "{kind}");
        assert!(s.references >= soup.len(), "{kind}: {} references", s.references);
        assert!(s.memory_bytes > 0 || kind == AccelKind::None, "{kind}: no memory reported");
        let mut c = Counters::default();
        let hits = rays.iter().filter(|r| accel.intersect(&soup, r, &mut c).is_some()).count();
        assert!(hits > 0, "{kind}: no ray hits the bunny");
        assert_eq!(c.rays, rays.len() as u64, "{kind}");
        assert!(c.prim_tests > 0, "{kind}: no primitive tests");
        match kind {
            AccelKind::None => {}
            AccelKind::Aabb => assert!(c.object_tests > 0, "{kind}: no object tests"),
            _ => assert!(c.nodes_visited > 0, "{kind}: no nodes visited"),
        }
        per_ray.push((kind, c.prim_tests as f64 / c.rays as f64));
    }
    let tests = |k: AccelKind| per_ray.iter().find(|(kind, _)| *kind == k).unwrap().1;
    assert!(tests(AccelKind::Bvh) * 20.0 < tests(AccelKind::None), "{per_ray:?}");
}

/// Long thin diagonal slivers: the case spatial splits exist for. The SBVH must duplicate
/// some references, and every structure must still agree with the oracle.
#[test]
fn long_diagonal_slivers() {
    let mut rng = Pcg32::new(12, 1);
    let tris: Vec<[Vec3; 3]> = (0..300)
        .map(|_| {
            let a = kit::random_point(&mut rng, &unit());
            let b = kit::random_point(&mut rng, &unit());
            [a, b, b + 0.02 * kit::random_dir(&mut rng)]
        })
        .collect();
    let soup = Soup::triangles(tris);
    let rays = kit::random_rays(&mut rng, 1000, &unit(), &unit());
    check_all("slivers", &soup, &rays);
    let sbvh = AnyAccel::build(AccelKind::Sbvh, &soup, &BuildOptions::default()).stats();
    assert!(sbvh.references > soup.len(), "no spatial split: {sbvh}");
}

/// A point of the lattice `{-2, -1.5, ..., 2}³`: vertices, edges and faces of lattice
/// triangles lie exactly on the planes that grids, kd-trees and spatial splits cut at.
fn lattice_point() -> impl Strategy<Value = Vec3> {
    (-4i32..=4, -4i32..=4, -4i32..=4).prop_map(|(x, y, z)| Vec3::new(x as f32, y as f32, z as f32) * 0.5)
}

fn lattice_prim() -> impl Strategy<Value = Prim> {
    prop_oneof![
        4 => [lattice_point(), lattice_point(), lattice_point()].prop_map(Prim::Triangle),
        1 => (lattice_point(), 1i32..=3).prop_map(|(center, r)| Prim::Sphere { center, radius: r as f32 * 0.25 }),
    ]
}

/// Rays from lattice points (often inside boxes, on faces or at vertices) along lattice
/// directions (axis-parallel, face and space diagonals), so they run through edges and
/// vertices and along planes exactly.
fn lattice_ray() -> impl Strategy<Value = Ray> {
    (lattice_point(), -1i32..=1, -1i32..=1, -1i32..=1)
        .prop_filter("direction must not be zero", |(_, x, y, z)| (*x, *y, *z) != (0, 0, 0))
        .prop_map(|(o, x, y, z)| Ray::new(o, Vec3::new(x as f32, y as f32, z as f32)))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn lattice_soups(prims in prop::collection::vec(lattice_prim(), 1..24), rays in prop::collection::vec(lattice_ray(), 1..48)) {
        let mut soup = Soup::new(prims[..prims.len() / 2].to_vec());
        soup.push_object(Soup::new(prims[prims.len() / 2..].to_vec()));
        check_all("lattice", &soup, &rays);
    }
}
