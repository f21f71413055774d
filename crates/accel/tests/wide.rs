//! Wide BVHs: the SIMD and portable kernels give bit-identical answers (same primitive,
//! distance and barycentrics), the counting and fast paths agree, and the layouts hold
//! the triangles they were built from.

use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters, Kernel, Prefetch, Primitives, PACKET};
use raylab_core::{Aabb, Pcg32, Ray, Vec3};
use raylab_testkit::{self as kit, Soup};

const WIDE: [AccelKind; 4] = [AccelKind::Bvh8, AccelKind::Bvh4, AccelKind::Bvh8Sbvh, AccelKind::Bvh8Q];

/// The SIMD kernels each test against the portable one (on a CPU without AVX-512,
/// `Avx512` falls back to `Simd` and the pair is tested twice).
const SIMD_KERNELS: [Kernel; 2] = [Kernel::Simd, Kernel::Avx512];

fn check_kernels_agree(name: &str, soup: &Soup, rays: &[Ray]) {
    // The SIMD walks with and without prefetching (which must not change an answer or
    // the work counted) against the portable walk, which never prefetches.
    let simd_walks = SIMD_KERNELS.into_iter().flat_map(|k| [(k, Prefetch::Off), (k, Prefetch::On)]);
    for (kind, (kernel, prefetch)) in WIDE.into_iter().flat_map(|k| simd_walks.clone().map(move |s| (k, s))) {
        let name = &format!("{name}/{kernel:?}/{prefetch:?}");
        let simd = AnyAccel::build(kind, soup, &BuildOptions::default()).with_kernel(kernel).with_prefetch(prefetch);
        assert_eq!(simd.prefetches_children(), Some(prefetch == Prefetch::On), "{name}/{kind}");
        let portable = AnyAccel::build(kind, soup, &BuildOptions::default()).with_kernel(Kernel::Portable).with_prefetch(Prefetch::Off);
        portable.validate(soup).unwrap_or_else(|e| panic!("{name}/{kind}: {e}"));
        let (mut cs, mut cp) = (Counters::default(), Counters::default());
        for (k, ray) in rays.iter().enumerate() {
            let (s, p) = (simd.intersect(soup, ray, &mut cs), portable.intersect(soup, ray, &mut cp));
            assert_eq!(s, p, "{name}/{kind} ray {k}: SIMD vs portable");
            assert_eq!(simd.intersect_fast(soup, ray), s, "{name}/{kind} ray {k}: fast vs counting path");
            assert_eq!(portable.intersect_fast(soup, ray), s, "{name}/{kind} ray {k}: portable fast path");
            let short = Ray { t_max: s.map_or(1.0, |h| h.t * 0.75), ..*ray };
            for r in [ray, &short] {
                let any = simd.occluded(soup, r, &mut cs);
                assert_eq!(portable.occluded(soup, r, &mut cp), any, "{name}/{kind} ray {k}: any hit");
                assert_eq!(simd.occluded_fast(soup, r), any, "{name}/{kind} ray {k}: fast any hit");
            }
        }
        // Same traversal, same work: the kernels differ only in how lanes are computed.
        assert_eq!(cs, cp, "{name}/{kind}: counters");
        assert!(cs.nodes_visited > 0 || soup.is_empty(), "{name}/{kind}: nothing counted");
    }
}

#[test]
fn simd_and_portable_agree_on_soups_and_degenerate_rays() {
    let mut rng = Pcg32::new(21, 1);
    let unit = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    for n in [0, 1, 5, 300, 3000] {
        let soup = kit::random_triangles(&mut rng, n, &unit, 0.2);
        let mut rays = kit::random_rays(&mut rng, 1000, &Aabb::new(Vec3::splat(-2.0), Vec3::splat(2.0)), &unit);
        // Rays lying in box planes (zero direction components): NaN slab distances.
        rays.push(Ray::new(Vec3::new(-2.0, 0.0, 0.0), Vec3::X));
        rays.push(Ray::new(Vec3::new(0.0, -2.0, 1.0), Vec3::Y));
        rays.push(Ray::new(Vec3::new(0.0, 0.0, 0.0), -Vec3::Z));
        check_kernels_agree(&format!("soup{n}"), &soup, &rays);
    }
    let mut mixed = kit::random_spheres(&mut rng, 200, &unit, 0.1);
    mixed.push_object(kit::random_triangles(&mut rng, 500, &unit, 0.1));
    mixed.push_object(kit::cube());
    let rays = kit::random_rays(&mut rng, 1000, &unit, &unit);
    check_kernels_agree("mixed", &mixed, &rays);
}

#[test]
fn simd_and_portable_agree_on_the_bunny() {
    let soup = kit::read_obj_triangles(&kit::asset("bunny_4968.obj"));
    let b = soup.bounds();
    let mut rng = Pcg32::new(22, 1);
    let rays = kit::random_rays(&mut rng, 3000, &Aabb::new(b.min - b.extent(), b.max + b.extent()), &b);
    check_kernels_agree("bunny", &soup, &rays);
}

/// Leaves hold full blocks: a wide tree over the bunny has far fewer nodes than the binary
/// one, at most eight triangles per leaf, and reports its layout.
#[test]
fn collapse_shape_on_the_bunny() {
    let soup = kit::read_obj_triangles(&kit::asset("bunny_4968.obj"));
    let bin = AnyAccel::build(AccelKind::Bvh, &soup, &BuildOptions::default()).stats();
    for (kind, width) in [(AccelKind::Bvh8, 8usize), (AccelKind::Bvh4, 4)] {
        let s = AnyAccel::build(kind, &soup, &BuildOptions::default()).stats();
        println!("{s}");
        assert_eq!(s.references, soup.len(), "{kind}: every triangle once");
        // A binary tree of n interior nodes has n + 1 leaves; opening up to `width` children
        // per wide node leaves at most about n / (width - 1) of them, plus partly filled ones.
        assert!(s.interior_nodes * (width - 1) <= 2 * bin.interior_nodes, "{kind}: {} wide nodes for {} binary", s.interior_nodes, bin.interior_nodes);
        assert!(s.max_depth < bin.max_depth, "{kind}: depth {} vs binary {}", s.max_depth, bin.max_depth);
        // The binary leaves hold at most 8 (`max_leaf`), and merged subtrees at most LEAF_PRIMS.
        assert_eq!(raylab_accel::wide::LEAF_PRIMS, 8);
        assert!(s.leaf_histogram.iter().skip(9).all(|&c| c == 0), "{kind}: leaves above 8: {:?}", s.leaf_histogram);
        assert!(s.notes.iter().any(|(k, v)| k == "width" && *v == width.to_string()));
    }
}

/// Rays aimed exactly at shared vertices and edges of a closed cube from inside: the
/// watertight kernel hits every one, through the SIMD filter too.
#[test]
fn watertight_from_inside_the_cube() {
    let soup = kit::cube();
    let mut rng = Pcg32::new(23, 1);
    let corners: Vec<Vec3> = (0..8).map(|k| Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, ((k >> 2) & 1) as f32) - 0.5).collect();
    for kind in WIDE {
        for kernel in [Kernel::Avx512, Kernel::Simd, Kernel::Portable] {
            let accel = AnyAccel::build(kind, &soup, &BuildOptions::default()).with_kernel(kernel);
            for _ in 0..2000 {
                let o = kit::random_point(&mut rng, &Aabb::new(Vec3::splat(-0.4), Vec3::splat(0.4)));
                let a = corners[rng.below(8) as usize];
                let b = corners[rng.below(8) as usize];
                for target in [a, 0.5 * (a + b)] {
                    let Some(d) = (target - o).try_normalize() else { continue };
                    let ray = Ray::new(o, d);
                    assert!(accel.intersect(&soup, &ray, &mut Counters::default()).is_some(), "{kind}/{kernel:?}: ray from {o} to {target} escaped");
                }
            }
        }
    }
}

/// A binary leaf too large for one leaf reference (more than 16 blocks) is spread over a
/// wide node of smaller leaves, and still answers as the oracle does.
#[test]
fn oversized_binary_leaf_is_split() {
    use raylab_accel::bvh::{Bvh, BvhNode};
    use raylab_accel::{QuantNode, WideBvh};
    let mut rng = Pcg32::new(24, 1);
    let unit = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let soup = kit::random_triangles(&mut rng, 300, &unit, 0.2);
    let bin = Bvh::from_parts(vec![BvhNode::leaf(soup.bounds(), 0, 300)], (0..300).collect(), 300, "one leaf");
    let oracle = AnyAccel::build(AccelKind::None, &soup, &BuildOptions::default());
    for kernel in [Kernel::Avx512, Kernel::Simd, Kernel::Portable] {
        let wide = WideBvh::<8>::from_binary(&bin, &soup, "bvh8").with_kernel(kernel);
        let quant = WideBvh::<8, QuantNode>::from_binary(&bin, &soup, "bvh8q").with_kernel(kernel);
        wide.validate(&soup).unwrap();
        quant.validate(&soup).unwrap();
        assert!(!wide.nodes.is_empty() && !quant.nodes.is_empty(), "the leaf was not split");
        let mut c = Counters::default();
        for ray in kit::random_rays(&mut rng, 500, &unit, &unit) {
            let want = oracle.intersect(&soup, &ray, &mut c).map(|h| h.t);
            assert_eq!(wide.intersect(&soup, &ray, &mut c).map(|h| h.t), want);
            assert_eq!(quant.intersect(&soup, &ray, &mut c).map(|h| h.t), want);
        }
    }
}

/// `rays` in packets of 16 through every wide layout and both kernels: each answer is
/// exactly the single-ray one (same primitive, distance and barycentrics).
fn check_packets_match_single(name: &str, soup: &Soup, rays: &[Ray]) -> usize {
    let mut hits = 0;
    for (kind, kernel) in WIDE.into_iter().flat_map(|k| SIMD_KERNELS.map(|s| (k, s))) {
        let name = &format!("{name}/{kernel:?}");
        let simd = AnyAccel::build(kind, soup, &BuildOptions::default()).with_kernel(kernel);
        let portable = AnyAccel::build(kind, soup, &BuildOptions::default()).with_kernel(Kernel::Portable);
        for (p, packet) in rays.chunks(PACKET).enumerate() {
            let (mut s, mut q) = (vec![None; packet.len()], vec![None; packet.len()]);
            simd.intersect_packet(soup, packet, &mut s);
            portable.intersect_packet(soup, packet, &mut q);
            for (i, ray) in packet.iter().enumerate() {
                let single = simd.intersect_fast(soup, ray);
                assert_eq!(s[i], single, "{name}/{kind} packet {p} ray {i}: SIMD packet vs single ray");
                assert_eq!(q[i], single, "{name}/{kind} packet {p} ray {i}: portable packet vs single ray");
                hits += usize::from(single.is_some());
            }
        }
    }
    hits
}

/// Camera rays in 4×4 tiles, as the ray files order them: `n × n` pixels of a pinhole
/// camera at `eye` looking at `target` with a field of view of `fov` radians.
fn camera_tiles(eye: Vec3, target: Vec3, fov: f32, n: usize) -> Vec<Ray> {
    let f = (target - eye).normalize();
    let r = f.cross(Vec3::Y).normalize();
    let u = r.cross(f);
    let half = (fov * 0.5).tan();
    let mut rays = Vec::new();
    for ty in (0..n).step_by(4) {
        for tx in (0..n).step_by(4) {
            for y in ty..ty + 4 {
                for x in tx..tx + 4 {
                    let sx = ((x as f32 + 0.5) / n as f32 * 2.0 - 1.0) * half;
                    let sy = ((y as f32 + 0.5) / n as f32 * 2.0 - 1.0) * half;
                    rays.push(Ray::new(eye, (f + sx * r + sy * u).normalize()));
                }
            }
        }
    }
    rays
}

#[test]
fn packets_answer_as_single_rays_coherent_and_incoherent() {
    let bunny = kit::read_obj_triangles(&kit::asset("bunny_4968.obj"));
    let b = bunny.bounds();
    let centre = 0.5 * (b.min + b.max);
    // Coherent tiles framing the bunny with margin: many rays miss.
    let eye = centre + Vec3::new(0.3, 0.2, 2.5) * b.extent().max_element();
    let tiles = camera_tiles(eye, centre, 0.6, 64);
    let hits = check_packets_match_single("bunny tiles", &bunny, &tiles);
    let runs = WIDE.len() * SIMD_KERNELS.len();
    assert!(hits > runs * 1000 && hits < runs * 64 * 64, "tiles should both hit and miss: {hits} hits");
    // Incoherent packets: random origins and directions, and a packet of rays that all miss.
    let mut rng = Pcg32::new(25, 1);
    let mut rays = kit::random_rays(&mut rng, 1600, &Aabb::new(b.min - b.extent(), b.max + b.extent()), &b);
    rays.extend((0..16).map(|k| Ray::new(b.max + Vec3::splat(1.0 + k as f32), Vec3::ONE.normalize())));
    // A short last packet.
    rays.truncate(rays.len() - 5);
    check_packets_match_single("bunny random", &bunny, &rays);
    // Ties: rays from inside the cube at its shared edges and corners hit two or three
    // triangles at the same distance; packets pick the same one as single rays.
    let corners: Vec<Vec3> = (0..8).map(|k| Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, ((k >> 2) & 1) as f32) - 0.5).collect();
    let mut ties = Vec::new();
    for _ in 0..800 {
        let o = kit::random_point(&mut rng, &Aabb::new(Vec3::splat(-0.4), Vec3::splat(0.4)));
        let (a, c) = (corners[rng.below(8) as usize], corners[rng.below(8) as usize]);
        ties.push(Ray::new(o, (0.5 * (a + c) - o).try_normalize().unwrap_or(Vec3::X)));
    }
    let cube = kit::cube();
    assert_eq!(check_packets_match_single("cube edges", &cube, &ties), runs * ties.len(), "every ray from inside hits");
}

/// Packets in an empty scene, of one ray, and of no rays.
#[test]
fn packet_edge_cases() {
    let soup = Soup::default();
    let accel = AnyAccel::build(AccelKind::Bvh8, &soup, &BuildOptions::default());
    let mut out = vec![Some(raylab_accel::Hit { t: 1.0, prim: 0, u: 0.0, v: 0.0 }); 3];
    accel.intersect_packet(&soup, &[Ray::new(Vec3::ZERO, Vec3::X); 3], &mut out);
    assert_eq!(out, vec![None; 3], "an empty scene: no hits, old answers cleared");
    let cube = kit::cube();
    let accel = AnyAccel::build(AccelKind::Bvh8, &cube, &BuildOptions::default());
    let mut one = [None];
    accel.intersect_packet(&cube, &[Ray::new(Vec3::new(0.0, 0.0, -2.0), Vec3::Z)], &mut one);
    assert_eq!(one[0].map(|h| h.t), Some(1.5), "the face z = -0.5 from z = -2");
    accel.intersect_packet(&cube, &[], &mut []);
}

/// `--build-quality` picks the builder under `bvh`, `bvh4` and `bvh8`: LBVH, binned SAH or
/// SBVH, the same trees as the structures of those names; every layout answers as the
/// oracle does.
#[test]
fn build_quality_picks_the_builder() {
    use raylab_accel::BuildQuality;
    let soup = kit::read_obj_triangles(&kit::asset("bunny_4968.obj"));
    let b = soup.bounds();
    let mut rng = Pcg32::new(26, 1);
    let rays = kit::random_rays(&mut rng, 500, &Aabb::new(b.min - b.extent(), b.max + b.extent()), &b);
    let oracle = AnyAccel::build(AccelKind::None, &soup, &BuildOptions::default());
    let stats = |kind, opts: &BuildOptions| {
        let s = AnyAccel::build(kind, &soup, opts).stats();
        (s.interior_nodes, s.leaves, s.references, s.max_depth, s.sah_cost.to_bits())
    };
    for (quality, same_as) in [(BuildQuality::Low, AccelKind::Lbvh), (BuildQuality::Medium, AccelKind::Bvh), (BuildQuality::High, AccelKind::Sbvh)] {
        let opts = BuildOptions { quality, ..Default::default() };
        assert_eq!(stats(AccelKind::Bvh, &opts), stats(same_as, &BuildOptions::default()), "{quality}: bvh is {same_as}'s tree");
        for kind in [AccelKind::Bvh, AccelKind::Bvh4, AccelKind::Bvh8, AccelKind::Bvh8Q] {
            let accel = AnyAccel::build(kind, &soup, &opts);
            accel.validate(&soup).unwrap_or_else(|e| panic!("{quality}/{kind}: {e}"));
            assert_eq!(accel.stats().name, kind.name());
            let mut c = Counters::default();
            for (k, ray) in rays.iter().enumerate() {
                kit::agrees_with_oracle(&soup, ray, oracle.intersect(&soup, ray, &mut c), accel.intersect(&soup, ray, &mut c)).unwrap_or_else(|e| panic!("{quality}/{kind} ray {k}: {e}"));
            }
        }
    }
    assert_eq!("ultra".parse::<BuildQuality>().unwrap_err(), "unknown build quality `ultra` (valid: low, medium, high)");
}

/// The quantised layout is `bvh8`'s tree with boxes rounded outward: the same answers to
/// the bit (hits are the least `(t, primitive)`, whatever the order), at least as many
/// node visits, the same triangle blocks, and nodes of 96 bytes instead of 224.
#[test]
fn quantised_nodes_answer_as_bvh8() {
    let soup = kit::read_obj_triangles(&kit::asset("bunny_4968.obj"));
    let b = soup.bounds();
    let mut rng = Pcg32::new(27, 1);
    let rays = kit::random_rays(&mut rng, 3000, &Aabb::new(b.min - b.extent(), b.max + b.extent()), &b);
    let f32_boxes = AnyAccel::build(AccelKind::Bvh8, &soup, &BuildOptions::default());
    let quant = AnyAccel::build(AccelKind::Bvh8Q, &soup, &BuildOptions::default());
    let (mut cf, mut cq) = (Counters::default(), Counters::default());
    for (k, ray) in rays.iter().enumerate() {
        assert_eq!(quant.intersect(&soup, ray, &mut cq), f32_boxes.intersect(&soup, ray, &mut cf), "ray {k}");
        assert_eq!(quant.occluded(&soup, ray, &mut cq), f32_boxes.occluded(&soup, ray, &mut cf), "ray {k}: any hit");
    }
    assert!(cq.nodes_visited >= cf.nodes_visited, "looser boxes cannot visit fewer nodes: {} < {}", cq.nodes_visited, cf.nodes_visited);
    // Looser by a few percent at most: 8 bits per bound leave boxes within 1/255 of their node.
    assert!((cq.nodes_visited as f64) < 1.1 * cf.nodes_visited as f64, "{} vs {} nodes", cq.nodes_visited, cf.nodes_visited);
    let (sf, sq) = (f32_boxes.stats(), quant.stats());
    assert_eq!((sq.interior_nodes, sq.leaves, sq.references), (sf.interior_nodes, sf.leaves, sf.references));
    let blocks = sf.memory_bytes - 224 * sf.interior_nodes;
    assert_eq!(sq.memory_bytes, blocks + 96 * sq.interior_nodes, "96-byte nodes, the same blocks");
    assert!(sq.notes.iter().any(|(k, v)| k == "boxes" && v == "quantised"));
}

/// The leaf rule, on a binary tree written by hand: two clusters of four triangles, each a
/// binary node over two leaves of two. A subtree of at most four references is one leaf (one
/// full block), never opened to fill the wide node's free slots: the 8-wide root gets two
/// leaves of four, not four leaves of two.
#[test]
fn subtrees_of_four_stay_one_leaf() {
    use raylab_accel::bvh::{Bvh, BvhNode};
    use raylab_accel::{QuantNode, WideBvh};
    let tri = |x: f32, k: f32| [Vec3::new(x, k, 0.0), Vec3::new(x + 1.0, k, 0.0), Vec3::new(x, k + 1.0, 0.5)];
    let soup = Soup::triangles((0..8).map(|i| tri(if i < 4 { 0.0 } else { 10.0 }, (i % 4) as f32)).collect::<Vec<_>>());
    let b = |r: std::ops::Range<u32>| r.fold(Aabb::EMPTY, |a, p| a.union(Primitives::bounds(&soup, p)));
    let nodes = vec![
        BvhNode::interior(b(0..8), 1),
        BvhNode::interior(b(0..4), 3),
        BvhNode::interior(b(4..8), 5),
        BvhNode::leaf(b(0..2), 0, 2),
        BvhNode::leaf(b(2..4), 2, 2),
        BvhNode::leaf(b(4..6), 4, 2),
        BvhNode::leaf(b(6..8), 6, 2),
    ];
    let bin = Bvh::from_parts(nodes, (0..8).collect(), 8, "hand-made");
    bin.validate(&soup).unwrap();
    let wide = WideBvh::<8>::from_binary(&bin, &soup, "bvh8");
    let quant = WideBvh::<8, QuantNode>::from_binary(&bin, &soup, "bvh8q");
    for s in [wide.stats(), quant.stats()] {
        assert_eq!((s.interior_nodes, s.leaves), (1, 2), "{}: {s}", s.name);
        assert_eq!(s.leaf_histogram[4], 2, "{}: two leaves of four", s.name);
    }
    assert_eq!(wide.blocks.len(), 2);
    assert!(wide.blocks.iter().all(|blk| blk.prim.iter().all(|&p| p != u32::MAX)), "both blocks full");
}

/// Prefetching is on by default only for structures of `PREFETCH_BYTES` and more:
/// a cube's is off, and so is it when forced off after being forced on; other structures
/// have none to set.
#[test]
fn prefetching_follows_the_structure_size_unless_forced() {
    let soup = kit::cube();
    for kind in [AccelKind::Bvh8, AccelKind::Bvh4, AccelKind::Bvh8Q] {
        let a = AnyAccel::build(kind, &soup, &BuildOptions::default());
        assert!(a.stats().memory_bytes < raylab_accel::wide::PREFETCH_BYTES);
        assert_eq!(a.prefetches_children(), Some(false), "{kind}: auto");
        let a = a.with_prefetch(Prefetch::On);
        assert_eq!(a.prefetches_children(), Some(true), "{kind}: on");
        assert_eq!(a.stats().notes.iter().find(|(k, _)| k == "prefetch").map(|(_, v)| v.as_str()), Some("entered and pushed children"));
        assert_eq!(a.with_prefetch(Prefetch::Auto).prefetches_children(), Some(false), "{kind}: auto again");
    }
    assert_eq!(AnyAccel::build(AccelKind::Bvh, &soup, &BuildOptions::default()).with_prefetch(Prefetch::On).prefetches_children(), None);
}
