//! The counting packet path (the renderer's camera rays): the same answers as single rays,
//! and each ray charged the work it took part in.

use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters, Hit, Kernel, PACKET};
use raylab_core::{Aabb, Pcg32, Ray, Vec3};
use raylab_testkit::{self as kit, Soup};

const KERNELS: [Kernel; 3] = [Kernel::Portable, Kernel::Simd, Kernel::Avx512];

fn counted(accel: &AnyAccel, soup: &Soup, rays: &[Ray]) -> (Vec<Option<Hit>>, Counters) {
    let mut out = vec![None; rays.len()];
    let mut c = Counters::default();
    accel.intersect_packet_counted(soup, rays, &mut out, &mut c);
    (out, c)
}

/// Sixteen copies of one ray walk the tree exactly as the ray alone does (the same boxes
/// entered, in the same order, the same pops dropped), so the packet is charged sixteen
/// times the single ray's nodes and tests.
#[test]
fn a_packet_of_copies_costs_sixteen_single_rays() {
    let mut rng = Pcg32::new(5, 9);
    let unit = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let soup = kit::random_triangles(&mut rng, 2000, &unit, 0.15);
    let rays = kit::random_rays(&mut rng, 200, &Aabb::new(Vec3::splat(-2.0), Vec3::splat(2.0)), &unit);
    for kind in [AccelKind::Bvh8, AccelKind::Bvh4, AccelKind::Bvh8Q] {
        for kernel in KERNELS {
            let accel = AnyAccel::build(kind, &soup, &BuildOptions::default()).with_kernel(kernel);
            let mut worked = 0;
            for (k, ray) in rays.iter().enumerate() {
                let mut single = Counters::default();
                let want = accel.intersect(&soup, ray, &mut single);
                let (got, c) = counted(&accel, &soup, &[*ray; PACKET]);
                assert!(got.iter().all(|h| *h == want), "{kind}/{kernel:?} ray {k}: answers");
                let n = PACKET as u64;
                assert_eq!(c, Counters { rays: n, nodes_visited: n * single.nodes_visited, prim_tests: n * single.prim_tests, object_tests: 0 }, "{kind}/{kernel:?} ray {k}");
                worked += (single.prim_tests > 0) as usize;
            }
            assert!(worked > 50, "{kind}/{kernel:?}: only {worked} rays reached triangles");
        }
    }
}

/// Three triangles make a wide BVH of one leaf (one block): every ray of a packet visits
/// that one node and tests its three triangles, whether it hits or not.
#[test]
fn one_leaf_charges_each_ray_one_node_and_its_triangles() {
    let soup = Soup::triangles([
        [Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)],
        [Vec3::new(0.0, 0.0, 2.0), Vec3::new(1.0, 0.0, 2.0), Vec3::new(0.0, 1.0, 2.0)],
        [Vec3::new(0.0, 0.0, 3.0), Vec3::new(1.0, 0.0, 3.0), Vec3::new(0.0, 1.0, 3.0)],
    ]);
    // Five rays down +z: three through the triangles' corner region (hit z = 1), two beside
    // them (miss, but inside the leaf's box in x and y: the box is [0, 1]², hit by both).
    let rays: Vec<Ray> = [(0.2, 0.2), (0.3, 0.1), (0.1, 0.3), (0.9, 0.9), (0.8, 0.7)].iter().map(|&(x, y)| Ray::new(Vec3::new(x, y, 0.0), Vec3::Z)).collect();
    for kind in [AccelKind::Bvh8, AccelKind::Bvh4, AccelKind::Bvh8Q] {
        for kernel in KERNELS {
            let accel = AnyAccel::build(kind, &soup, &BuildOptions::default()).with_kernel(kernel);
            let (hits, c) = counted(&accel, &soup, &rays);
            let ts: Vec<Option<f32>> = hits.iter().map(|h| h.map(|h| h.t)).collect();
            assert_eq!(ts, [Some(1.0), Some(1.0), Some(1.0), None, None], "{kind}/{kernel:?}");
            assert_eq!(hits[0].unwrap().prim, 0);
            assert_eq!(c, Counters { rays: 5, nodes_visited: 5, prim_tests: 15, object_tests: 0 }, "{kind}/{kernel:?}");
        }
    }
}

/// Structures without packets trace the rays one by one, counting as they always do.
#[test]
fn other_structures_count_ray_by_ray() {
    let mut rng = Pcg32::new(8, 2);
    let unit = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let soup = kit::random_triangles(&mut rng, 300, &unit, 0.2);
    let rays = kit::random_rays(&mut rng, PACKET, &unit, &unit);
    for kind in [AccelKind::Bvh, AccelKind::KdTree, AccelKind::Grid] {
        let accel = AnyAccel::build(kind, &soup, &BuildOptions::default());
        assert!(!accel.has_packets());
        let mut single = Counters::default();
        let want: Vec<Option<Hit>> = rays.iter().map(|r| accel.intersect(&soup, r, &mut single)).collect();
        assert_eq!(counted(&accel, &soup, &rays), (want, single), "{kind}");
    }
}
