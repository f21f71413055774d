//! Every peer in this build against raylab's brute-force oracle on the 4,968-triangle
//! bunny: random closest-hit rays, any-hit segments and (for every peer) 16-ray packets,
//! within the tolerance of `raylab_peers::agree`. Built only with the features
//! (`cargo test -p raylab-peers --features peers,embree`); without them there is no peer.
#![cfg(any(feature = "obvhs", feature = "bvh", feature = "embree"))]

use raylab_accel::{AccelKind, AnyAccel, BuildOptions, Primitives};
use raylab_core::{Aabb, Pcg32, Ray, Vec3};
use raylab_peers::{agree, harness, PeerKind, RaylabPeer, PACKET};
use raylab_testkit::{asset, random_rays, read_obj_triangles};

fn kinds() -> Vec<PeerKind> {
    [PeerKind::Embree, PeerKind::EmbreeMedium, PeerKind::EmbreeRobust, PeerKind::ObvhsCwbvh, PeerKind::ObvhsBvh2, PeerKind::BvhCrate].into_iter().filter(|k| k.available()).collect()
}

#[test]
fn every_peer_agrees_with_the_oracle_on_the_bunny() {
    let soup = read_obj_triangles(&asset("bunny_4968.obj"));
    let tris: Vec<[Vec3; 3]> = (0..soup.len() as u32).map(|i| soup.triangle(i).unwrap()).collect();
    assert_eq!(tris.len(), 4968);
    let b = soup.bounds();
    let around = Aabb::new(b.min - b.extent(), b.max + b.extent());
    let mut rng = Pcg32::new(11, 0);
    let rays = random_rays(&mut rng, 20_000, &around, &b);
    // Segments ending half way to the far side of the bounds: some blocked, some not.
    let segments: Vec<Ray> = rays.iter().map(|r| Ray::segment(r.origin, r.dir, 0.0, (b.centroid() - r.origin).length())).collect();
    let oracle = RaylabPeer { kind: AccelKind::None, accel: AnyAccel::build(AccelKind::None, &soup, &BuildOptions::default()), prims: &soup, mesh_bytes: 0 };
    let mut want = vec![None; rays.len()];
    harness::closest(&oracle, &rays, &mut want);
    let mut want_any = vec![false; rays.len()];
    harness::occluded(&oracle, &segments, &mut want_any);
    let hits = want.iter().flatten().count();
    let blocked = want_any.iter().filter(|&&x| x).count();
    assert!(hits > 4000 && blocked > 2000 && blocked < hits, "a test that hits too little proves nothing: {hits} hits, {blocked} blocked");
    // Packets: consecutive rays, 16 at a time (the last one short).
    let packets: Vec<(u32, u32)> = (0..rays.len()).step_by(PACKET).map(|s| (s as u32, (s + PACKET).min(rays.len()) as u32)).collect();

    let threads = rayon::current_num_threads();
    for kind in kinds() {
        let peer = raylab_peers::build(kind, &tris, threads).unwrap();
        assert!(peer.memory_bytes() > 20 * tris.len(), "{}: {} bytes cannot hold 4968 triangles", peer.name(), peer.memory_bytes());
        let mut got = vec![None; rays.len()];
        harness::closest(peer.as_ref(), &rays, &mut got);
        let a = agree::closest(&want, &got);
        eprintln!("{}: {} bytes, {} of {} closest hits disagree", peer.name(), peer.memory_bytes(), a.disagreeing, a.rays);
        assert!(a.ok(), "{}: closest hits: {a:?}", peer.name());
        assert!(a.t_sum_rel_diff() < 1e-4, "{}: {a:?}", peer.name());
        // Rays that agree with the oracle report a primitive the ray really hits there.
        for (r, (w, g)) in rays.iter().zip(want.iter().zip(&got)) {
            if let (Some(w), Some(g)) = (w, g) {
                if (w.t - g.t).abs() <= agree::REL_T_TOLERANCE * w.t && g.prim != w.prim {
                    let again = raylab_core::intersect::triangle_plane_t(r, tris[g.prim as usize][0], tris[g.prim as usize][1], tris[g.prim as usize][2]);
                    assert!(((again as f32) - g.t).abs() <= 1e-3 * g.t, "{}: prim {} is not at t = {}", peer.name(), g.prim, g.t);
                }
            }
        }
        let mut got_any = vec![false; rays.len()];
        harness::occluded(peer.as_ref(), &segments, &mut got_any);
        let a = agree::any(&want_any, &got_any);
        assert!(a.ok(), "{}: any hit: {a:?}", peer.name());
        let mut got16 = vec![None; rays.len()];
        harness::closest_packets(peer.as_ref(), &rays, &packets, &mut got16);
        let a = agree::closest(&got, &got16);
        assert!(a.ok() && a.disagreeing == 0, "{}: packets and single rays answer alike: {a:?}", peer.name());
    }
}
