//! The ray-major walk at both widths against single-ray traversal and the single-ray
//! kernels. Each test runs for every width this CPU has (AVX2: 8 rays; AVX-512: 16) and
//! says which it skips.

use raylab_core::{Pcg32, Ray, Vec3};

use super::avx2::X8;
use super::avx512::X16;
use super::{Packet, Vector, ROBUST_FAR};
use crate::wide::packet::PACKET;
use crate::wide::{node::Layout, node::WideNode, quant::QuantNode, WideBvh};
use crate::{binary_for_wide, BuildOptions, Counters, PrimHit, Primitives};

/// Runs `f8` with the AVX2 token and `f16` with the AVX-512 one, where the CPU has them.
fn widths(f8: fn(X8), f16: fn(X16)) {
    match X8::detect() {
        Some(v) => f8(v),
        None => eprintln!("no AVX2 on this CPU: the 8-ray ray-major path is not run"),
    }
    match X16::detect() {
        Some(v) => f16(v),
        None => eprintln!("no AVX-512 on this CPU: the 16-ray ray-major path is not run"),
    }
}

/// The lanes of `x`.
fn lanes<V: Vector>(v: V, x: V::F) -> Vec<f32> {
    v.store(x).as_ref().to_vec()
}

/// Triangles (through the packed blocks) then spheres (lanes that are not triangles).
pub(in crate::wide) struct Mixed {
    pub(in crate::wide) tris: Vec<[Vec3; 3]>,
    spheres: Vec<(Vec3, f32)>,
}

impl Mixed {
    /// One triangle at `z = 2`, facing rays from the origin along `+z`.
    fn one_triangle() -> Mixed {
        Mixed { tris: vec![[Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0)]], spheres: vec![] }
    }
}

impl Primitives for Mixed {
    fn len(&self) -> usize {
        self.tris.len() + self.spheres.len()
    }
    fn bounds(&self, i: u32) -> raylab_core::Aabb {
        match self.triangle(i) {
            Some(t) => raylab_core::Aabb::from_points(t),
            None => {
                let (c, r) = self.spheres[i as usize - self.tris.len()];
                raylab_core::Aabb::new(c - r, c + r)
            }
        }
    }
    fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
        match self.triangle(i) {
            Some([a, b, c]) => raylab_core::intersect::triangle(ray, a, b, c).map(|(t, u, v)| PrimHit { t, u, v }),
            None => {
                let (c, r) = self.spheres[i as usize - self.tris.len()];
                raylab_core::intersect::sphere(ray, c, r).map(|t| PrimHit { t, u: 0.0, v: 0.0 })
            }
        }
    }
    fn triangle(&self, i: u32) -> Option<[Vec3; 3]> {
        self.tris.get(i as usize).copied()
    }
}

/// Random small triangles, a grid of quads whose shared edges and vertices rays pass
/// through, a triangle repeated under three indices (exact ties: the lowest index
/// wins), zero-area triangles (the scalar kernel's cases), and spheres.
pub(in crate::wide) fn scene(rng: &mut Pcg32) -> Mixed {
    let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
    let mut tris: Vec<[Vec3; 3]> = (0..600).map(|_| {
        let c = r();
        [c, c + 0.2 * r(), c + 0.2 * r()]
    }).collect();
    for i in 0..8 {
        for j in 0..8 {
            let p = |a: i32, b: i32| Vec3::new((i + a) as f32 * 0.25 - 1.0, (j + b) as f32 * 0.25 - 1.0, 0.5);
            tris.push([p(0, 0), p(1, 0), p(1, 1)]);
            tris.push([p(0, 0), p(1, 1), p(0, 1)]);
        }
    }
    let dup = [Vec3::new(-0.5, -0.5, -0.9), Vec3::new(0.5, -0.5, -0.9), Vec3::new(0.0, 0.5, -0.9)];
    tris.extend([dup; 3]);
    let p = r();
    tris.extend([[p, p, p], [p, p + Vec3::X * 0.1, p + Vec3::X * 0.2]]);
    let spheres = (0..40).map(|k| (r(), 0.05 + 0.0025 * k as f32)).collect();
    Mixed { tris, spheres }
}

/// Packets of 1 to 16 rays from one origin in a narrow cone (a camera tile), some with
/// a `t_min` above zero or a short `t_max`, and some through grid vertices exactly.
pub(in crate::wide) fn packets(rng: &mut Pcg32, prims: &Mixed) -> Vec<Vec<Ray>> {
    (0..400).map(|k| {
        // Every eleventh packet leaves a point of a tilted triangle (hits at t within
        // the error bound of zero, some decided by the scalar kernel).
        let origin = if k % 11 == 0 {
            let [a, b, c] = prims.tris[k];
            a + 0.3 * (b - a) + 0.3 * (c - a)
        } else {
            Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 6.0 - 3.0
        };
        let aim = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
        let n = if k % 5 == 0 { 1 + k % PACKET } else { PACKET };
        (0..n).map(|r| {
            let target = if k % 11 == 0 { origin + Vec3::new((r % 4) as f32 - 1.5, (r / 4) as f32 - 1.5, if k % 2 == 0 { 2.0 } else { -2.0 }) } else if k % 7 == 0 { Vec3::new((r % 4) as f32 * 0.25 - 0.5, (r / 4) as f32 * 0.25 - 0.5, 0.5) } else { aim + Vec3::new((r % 4) as f32, (r / 4) as f32, 0.0) * 0.02 };
            let mut ray = Ray::new(origin, target - origin);
            if k % 3 == 0 {
                ray.t_min = 0.3;
            }
            if k % 4 == 1 {
                ray.t_max = 0.5 + r as f32 * 0.05;
            }
            ray
        }).collect()
    }).collect()
}

/// Every packet, cut into packets of the width, against its rays alone; at least
/// `min_taken` 16-ray packets' worth through the ray-major path and `min_hits` hits.
fn check<V: Vector, N: Layout<8>>(v: V, bvh: &WideBvh<8, N>, prims: &Mixed, packets: &[Vec<Ray>], min_taken: usize, min_hits: usize) {
    let (mut taken, mut hits) = (0, 0);
    for (k, rays) in packets.iter().flat_map(|p| p.chunks(V::RAYS)).enumerate() {
        let mut out = vec![None; rays.len()];
        let mut counted = vec![None; rays.len()];
        let mut c = Counters::default();
        let took = super::closest::<V, _, 8, N, false>(v, bvh, prims, rays, &mut out, &mut Counters::default());
        assert_eq!(super::closest::<V, _, 8, N, true>(v, bvh, prims, rays, &mut counted, &mut c), took);
        if !took {
            assert!(out.iter().all(Option::is_none), "{} rays, packet {k}: declined, yet answers written", V::RAYS);
            continue;
        }
        taken += 1;
        for (r, ray) in rays.iter().enumerate() {
            let want = crate::wide::traverse::closest::<_, 8, N, true, false, false>(bvh, prims, ray, &mut Counters::default());
            assert_eq!(out[r], want, "{} rays, packet {k} ray {r}", V::RAYS);
            assert_eq!(counted[r], want, "{} rays, packet {k} ray {r}: counting build", V::RAYS);
            hits += usize::from(want.is_some());
        }
        assert_eq!(c.rays, rays.len() as u64, "packet {k}");
        // Copies of a ray walk as the ray does alone: as many times its work.
        let copies = vec![rays[0]; V::RAYS];
        let (mut cn, mut c1) = (Counters::default(), Counters::default());
        assert!(super::closest::<V, _, 8, N, true>(v, bvh, prims, &copies, &mut vec![None; V::RAYS], &mut cn));
        crate::wide::traverse::closest::<_, 8, N, true, true, false>(bvh, prims, &rays[0], &mut c1);
        let n = V::RAYS as u64;
        assert_eq!((cn.nodes_visited, cn.prim_tests), (n * c1.nodes_visited, n * c1.prim_tests), "{} rays, packet {k}: copies", V::RAYS);
    }
    let min_taken = min_taken * (PACKET / V::RAYS);
    assert!(taken >= min_taken && hits >= min_hits, "{} rays: too few packets through the ray-major path: {taken} packets, {hits} hits", V::RAYS);
}

fn coherent_packets<V: Vector>(v: V) {
    let mut rng = Pcg32::new(11, 3);
    let prims = scene(&mut rng);
    let packets = packets(&mut rng, &prims);
    let binary = binary_for_wide(&prims, &BuildOptions::default(), "bvh");
    check(v, &WideBvh::<8, WideNode<8>>::from_binary(&binary, &prims, "bvh8"), &prims, &packets, 300, 2000);
    check(v, &WideBvh::<8, QuantNode>::from_binary(&binary, &prims, "bvh8q"), &prims, &packets, 300, 2000);
}

#[test]
fn coherent_packets_get_their_single_ray_answers() {
    widths(coherent_packets, coherent_packets);
}

/// The ray-major triangle kernel decides each ray as `triangles_sse` decides that ray
/// alone: the same hits with the same bits of `t` and barycentrics, and the same rays
/// left to the scalar kernel. Random, degenerate, tiny and huge triangles, origins on
/// the triangles (t within the error bound of zero) and limited `t` ranges.
fn triangle_kernel<V: Vector>(v: V) {
    use crate::wide::kernels::triangles_sse;
    use raylab_core::intersect::ShearedRay;
    let mut rng = Pcg32::new(13, 5);
    let mut r = |scale: f32| Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5) * scale;
    let (mut hits, mut exact, mut packets) = (0, 0, 0);
    // Rows of four rays, centred on the aim.
    let rows = (V::RAYS / 4 - 1) as f32 / 2.0;
    for k in 0..6000 {
        let scale = [1.0, 1e-30, 1e30, 3e38, 1e6][k % 5];
        let b = crate::wide::kernels::tests::random_block(k, 4, scale, &mut r);
        let origin = match k % 3 {
            0 => r(2.0 * scale),
            1 => Vec3::ZERO,
            _ => b.vertex(2, 0) + 0.3 * (b.vertex(2, 1) - b.vertex(2, 0)) + 0.3 * (b.vertex(2, 2) - b.vertex(2, 0)),
        };
        let aim = (b.vertex(k % 4, 0) + b.vertex(k % 4, 1) + b.vertex(k % 4, 2)) / 3.0 - origin;
        let rays: Vec<Ray> = (0..V::RAYS).map(|q| {
            let d = aim + Vec3::new((q % 4) as f32 - 1.5, (q / 4) as f32 - rows, 0.0) * 0.01 * aim.length();
            let mut ray = Ray::new(origin, if k % 11 == 0 { -d } else { d });
            if k % 4 == 0 {
                ray.t_max = 0.9 + 0.01 * q as f32;
            }
            ray
        }).collect();
        let Some((p, t_max)) = Packet::new(v, &rays) else { continue };
        packets += 1;
        let t_maxes = lanes(v, t_max);
        for j in 0..4 {
            let (hit, ex, t, u, w) = super::triangle(v, &b, j, &p, p.axes, V::ALL, t_max);
            let (t, u, w) = (lanes(v, t), lanes(v, u), lanes(v, w));
            for (q, ray) in rays.iter().enumerate() {
                let one = triangles_sse(&b, &ShearedRay::new(ray), ray.t_min, t_maxes[q]);
                let bit = 1 << j;
                assert_eq!((hit >> q & 1 != 0, ex >> q & 1 != 0), (one.hit & bit != 0, one.exact & bit != 0), "{} rays, block {k} triangle {j} ray {q}", V::RAYS);
                if one.hit & bit != 0 {
                    assert_eq!([t[q], u[q], w[q]].map(f32::to_bits), [one.t[j], one.u[j], one.v[j]].map(f32::to_bits), "{} rays, block {k} triangle {j} ray {q}", V::RAYS);
                    hits += 1;
                }
                exact += usize::from(one.exact & bit != 0);
            }
        }
    }
    assert!(packets > 3000 && hits > 625 * V::RAYS && exact > 62 * V::RAYS, "{} rays: too few cases: {packets} packets, {hits} hits, {exact} left to the scalar kernel", V::RAYS);
}

#[test]
fn the_triangle_kernel_matches_the_four_wide_kernel_ray_by_ray() {
    widths(triangle_kernel, triangle_kernel);
}

/// The frustum test keeps every child that any ray of the packet enters, with an entry
/// distance no greater than that ray's: random boxes (empty, flat, huge and tiny ones
/// among them) against packets over narrow and wide cones, some from scattered origins.
fn frustum_keeps<V: Vector>(v: V) {
    use crate::wide::kernels::slabs_avx2;
    use crate::wide::ray::RayBoxes;
    use std::arch::x86_64::*;
    let mut rng = Pcg32::new(17, 9);
    let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
    let (mut entered, mut culled, mut packets) = (0, 0, 0);
    let rows = (V::RAYS / 4 - 1) as f32 / 2.0;
    for k in 0..3000 {
        let scale = [1.0, 1e-3, 1e4][k % 3];
        let mut node = WideNode::<8>::EMPTY_NODE;
        for l in 0..8 - k % 3 {
            let (c, e) = (r() * 2.0 * scale, (r().abs() + Vec3::splat(if l == 3 { 0.0 } else { 0.01 })) * scale);
            let e = if l == 2 { Vec3::new(e.x, 0.0, e.z) } else { e };
            node.set(l, &raylab_core::Aabb::new(c - e, c + e), l as u32);
        }
        let origin = r() * 5.0 * scale;
        let target = node.child_bounds(k % 5);
        let aim = (target.min + target.max) * 0.5 - origin;
        let spread = [0.01, 0.2, 1.0][k % 3] * aim.length();
        let rays: Vec<Ray> = (0..V::RAYS).map(|q| {
            let o = if k % 4 == 0 { origin + r() * 0.5 * scale } else { origin };
            let mut ray = Ray::new(o, aim + Vec3::new((q % 4) as f32 - 1.5, (q / 4) as f32 - rows, 0.0) * spread * 0.1);
            ray.t_min = if k % 5 == 0 { 0.1 * q as f32 } else { 0.0 };
            ray.t_max = if k % 6 == 0 { 1.0 + q as f32 } else { f32::INFINITY };
            ray
        }).collect();
        let Some((p, t_max)) = Packet::new(v, &rays) else { continue };
        let f = p.frustum.as_ref().expect("finite constants give a frustum");
        packets += 1;
        // Each ray's far limit for box tests, as the walk computes it.
        let far_each = lanes(v, v.mul(t_max, v.splat(ROBUST_FAR)));
        let far_max = far_each.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let mut bound = [0.0f32; 8];
        // SAFETY: every width's token implies AVX2; `bound` holds 8 f32.
        let kept = unsafe {
            let (kept, t0) = super::frustum_slabs(&node, f, p.near_rows, p.far_rows, far_max);
            _mm256_storeu_ps(bound.as_mut_ptr(), t0);
            kept
        };
        let mut any = 0u32;
        for (q, &far_q) in far_each.iter().enumerate() {
            let (mut near, mut exit) = ([0.0f32; 8], [0.0f32; 8]);
            // SAFETY: as above.
            unsafe {
                let (n, x) = slabs_avx2(&node, &RayBoxes::new(&rays[q]), far_q);
                _mm256_storeu_ps(near.as_mut_ptr(), n);
                _mm256_storeu_ps(exit.as_mut_ptr(), x);
            }
            for l in 0..8 {
                if near[l] <= exit[l] {
                    any |= 1 << l;
                    assert!(kept & 1 << l != 0, "{} rays, packet {k}: ray {q} enters child {l}, culled by the frustum", V::RAYS);
                    assert!(bound[l] <= near[l], "{} rays, packet {k}: child {l}: frustum entry {} above ray {q}'s {}", V::RAYS, bound[l], near[l]);
                }
            }
        }
        entered += any.count_ones();
        culled += (!kept & 0xFF).count_ones();
    }
    assert!(packets > 2000 && entered > 3000 && culled > 3000, "{} rays: too few cases: {packets} packets, {entered} children entered, {culled} culled", V::RAYS);
}

#[test]
fn the_frustum_keeps_every_child_a_ray_enters() {
    widths(frustum_keeps, frustum_keeps);
}

/// The packet's constants, loaded by the transpose and reduced, are each ray's own
/// (`RayBoxes::new`, `ShearedRay::new`) and their exact extremes, for packets of 1 to
/// the width's rays (lanes past the count repeat the last ray).
fn constants<V: Vector>(v: V) {
    use crate::wide::ray::RayBoxes;
    use raylab_core::intersect::ShearedRay;
    let mut rng = Pcg32::new(3, 9);
    let mut f = |s: f32| (rng.next_f32() - 0.5) * s;
    let mut taken = 0;
    for k in 0..400 {
        let n = 1 + k % V::RAYS;
        let rays: Vec<Ray> = (0..n).map(|_| Ray::segment(Vec3::new(f(8.0), f(8.0), f(8.0)), Vec3::new(0.3 + f(0.2), -0.2 + f(0.2), 1.0 + f(0.4)), f(0.1).abs(), 5.0 + f(4.0))).collect();
        let Some((p, t_max)) = Packet::new(v, &rays) else { continue };
        taken += 1;
        let fr = p.frustum.as_ref().expect("finite constants");
        for r in 0..V::RAYS {
            let ray = &rays[r.min(n - 1)];
            let (rb, sh) = (RayBoxes::new(ray), ShearedRay::new(ray));
            let bits = |x: &[f32]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            let got = |xs: &[V::F]| xs.iter().map(|&x| lanes(v, x)[r]).collect::<Vec<_>>();
            assert_eq!(bits(&got(&p.origin)), bits(&rb.origin), "packet {k} ray {r}: origin");
            assert_eq!(bits(&got(&p.inv)), bits(&rb.inv), "packet {k} ray {r}: inverse");
            assert_eq!(bits(&got(&p.inv_far)), bits(&rb.inv_far), "packet {k} ray {r}: inverse for far planes");
            assert_eq!(bits(&got(&p.shear)), bits(&[sh.sx, sh.sy, sh.sz]), "packet {k} ray {r}: shear");
            assert_eq!((lanes(v, p.t_min)[r], lanes(v, t_max)[r]), (rb.t_min, ray.t_max), "packet {k} ray {r}: interval");
            assert_eq!(p.axes, (sh.kx, sh.ky, sh.kz), "packet {k}: shear axes");
            assert_eq!((p.near_rows, p.far_rows), (rb.near, rb.far), "packet {k}: box rows");
            assert_eq!(p.sheared(r).origin, ray.origin, "packet {k} ray {r}: stored origin");
        }
        let ext = |g: &dyn Fn(&Ray) -> f32| (rays.iter().map(g).fold(f32::INFINITY, f32::min), rays.iter().map(g).fold(f32::NEG_INFINITY, f32::max));
        for a in 0..3 {
            let (lo, hi) = ext(&|r: &Ray| r.origin[a]);
            let (near, far) = if p.near_rows[a] == a { (hi, lo) } else { (lo, hi) };
            assert_eq!((fr.near_origin[a], fr.far_origin[a]), (near, far), "{} rays, packet {k} axis {a}: frustum origins", V::RAYS);
            let (lo, hi) = ext(&|r: &Ray| RayBoxes::new(r).inv[a]);
            assert_eq!(fr.inv[a], [lo, hi], "{} rays, packet {k} axis {a}: frustum inverses", V::RAYS);
        }
        assert_eq!(fr.t_min, ext(&|r: &Ray| r.t_min + 0.0).0, "{} rays, packet {k}: frustum t_min", V::RAYS);
    }
    assert!(taken > 300, "{} rays: too few packets taken: {taken}", V::RAYS);
}

#[test]
fn packet_constants_are_each_rays_own_and_their_extremes() {
    widths(constants, constants);
}

/// A ray with a zero direction component has an infinite inverse: no frustum, and the
/// packet still gets its single-ray answers.
fn infinite_inverse<V: Vector>(v: V) {
    let step = 1.6 / V::RAYS as f32;
    let rays: Vec<Ray> = (0..V::RAYS).map(|q| Ray::new(Vec3::new(0.01 * q as f32, 0.0, 0.0), Vec3::new(0.0, 0.1, 1.0))).collect();
    assert!(Packet::new(v, &rays).is_some_and(|(p, _)| p.frustum.is_none()));
    let mut rng = Pcg32::new(5, 7);
    let prims = scene(&mut rng);
    let bvh = WideBvh::<8, WideNode<8>>::from_binary(&binary_for_wide(&prims, &BuildOptions::default(), "bvh"), &prims, "bvh8");
    let packets: Vec<Vec<Ray>> = (0..50).map(|k| (0..V::RAYS).map(|q| Ray::new(Vec3::new(-0.9 + 0.036 * k as f32, -0.9 + step * q as f32, -3.0), Vec3::new(0.0, 0.05, 1.0))).collect()).collect();
    check(v, &bvh, &prims, &packets, 40 * V::RAYS / PACKET, 100);
}

#[test]
fn packets_with_an_infinite_inverse_have_no_frustum() {
    widths(infinite_inverse, infinite_inverse);
}

fn declined<V: Vector>(v: V) {
    let prims = Mixed::one_triangle();
    let bvh = WideBvh::<8, WideNode<8>>::from_binary(&binary_for_wide(&prims, &BuildOptions::default(), "bvh"), &prims, "bvh8");
    let run = |dirs: &[Vec3]| {
        let rays: Vec<Ray> = dirs.iter().map(|&d| Ray::new(Vec3::ZERO, d)).collect();
        let mut out = vec![None; rays.len()];
        let took = super::closest::<V, _, 8, WideNode<8>, false>(v, &bvh, &prims, &rays, &mut out, &mut Counters::default());
        (took, out)
    };
    // Along +z, all: taken, both hit at t = 2 (direction z = 1).
    let (took, out) = run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(0.2, 0.1, 1.0)]);
    assert!(took);
    assert_eq!(out.iter().map(|h| h.map(|h| (h.prim, h.t))).collect::<Vec<_>>(), [Some((0, 2.0)); 2]);
    // One ray with a negative x: other box rows.
    assert!(!run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(-0.1, 0.1, 1.0)]).0);
    // One ray mostly along x: other shear axes.
    assert!(!run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(2.0, 0.1, 1.0)]).0);
    // Along -z for one: other signs and a swapped shear.
    assert!(!run(&[Vec3::new(0.1, 0.1, 1.0), Vec3::new(0.1, 0.1, -1.0)]).0);
}

#[test]
fn packets_of_mixed_octants_or_axes_are_declined() {
    widths(declined, declined);
}
