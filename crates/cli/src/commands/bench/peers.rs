//! `raylab bench --peers embree,obvhs,bvh`: other engines' structures (crates/peers) on
//! exactly the rays raylab traces, interleaved with raylab's best structures in one run.
//! Every structure, raylab's included, is traced through the same calls (one `Peer` trait
//! object, one rayon loop) and checked ray by ray against raylab's oracle within the
//! tolerance of `raylab_peers::agree`; speeds are printed as ratios to Embree HIGH, by CPU
//! time (stable on a shared machine) and by wall clock. Method and figures:
//! docs/performance.md, "Peers, side by side".

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Primitives};
use raylab_core::{Ray, Vec3};
use raylab_lab::bench::{cpu_name, median, Machine};
use raylab_lab::{rays, RayKind};
use raylab_loader::Overrides;
use raylab_peers::harness::{self, Timing, TilePackets};
use raylab_peers::table::{self, Clock, Row, Speed};
use raylab_peers::{agree, Peer, PeerHit, PeerKind, RaylabPeer};
use serde::Serialize;

use super::BenchArgs;

/// The name of the packet ray set: the primary rays in 4×4 tiles, 16 rays per call for
/// structures with a packet kernel (Embree's `rtcIntersect16`), one by one for the others.
const PACKETS: &str = "primary16";
/// The structure the ratios are taken to.
const REFERENCE: &str = "embree high";
/// Embree with the guarantees raylab's kernels give (box tests that rounding cannot make
/// miss, watertight triangles): the second reference, for the price of those guarantees.
const ROBUST: &str = "embree high robust";

#[derive(Serialize)]
struct PeersReport {
    machine: Machine,
    raylab_version: String,
    repeats: u32,
    resolution: u32,
    /// `agree::REL_T_TOLERANCE` and `agree::DISAGREEING_PER_RAY`.
    tolerance: Tolerance,
    scenes: Vec<SceneFigures>,
}

#[derive(Serialize)]
struct Tolerance {
    relative_t: f32,
    disagreeing_per_ray: f64,
}

#[derive(Serialize)]
struct SceneFigures {
    scene: String,
    triangles: usize,
    oracle: String,
    structures: Vec<StructureFigures>,
}

#[derive(Serialize)]
struct StructureFigures {
    name: String,
    build_ms: f64,
    memory_bytes: usize,
    bytes_per_triangle: f64,
    /// Per ray set (primary, diffuse, shadow, primary16); empty for build-only peers.
    rays: BTreeMap<String, KindFigures>,
}

#[derive(Serialize)]
struct KindFigures {
    #[serde(flatten)]
    speed: Speed,
    /// Ratio to Embree HIGH by CPU time, when Embree ran.
    ratio_to_embree: Option<f64>,
    /// Ratio to Embree HIGH with `RTC_SCENE_FLAG_ROBUST` by CPU time, when it ran.
    ratio_to_embree_robust: Option<f64>,
    agreement: agree::Agreement,
}

/// One traced ray set: its name, rays, packets (for `primary16`) and the oracle's answers.
struct Set {
    name: String,
    any_hit: bool,
    rays: Vec<Ray>,
    packets: Option<Vec<(u32, u32)>>,
    closest: Vec<Option<PeerHit>>,
    occluded: Vec<bool>,
}

pub fn run(a: &BenchArgs, peers: &str) -> Result<()> {
    let peer_kinds = raylab_peers::parse_list(peers)?;
    if a.report.is_some() || a.dump_rays.is_some() {
        bail!("--peers writes tables and --json only: leave out --report and --dump-rays (run `raylab bench` without --peers for them)");
    }
    // raylab's best structure by default (docs/performance.md); any list by name.
    let accels = if a.accels == "all" { vec![AccelKind::Bvh8] } else { raylab_lab::sweep::parse_list::<AccelKind>("--accels", &a.accels).map_err(|e| anyhow::anyhow!("{e}"))? };
    let kinds: Vec<RayKind> = a.rays.split(',').map(|s| s.trim().parse::<RayKind>().map_err(|e| anyhow::anyhow!("--rays: {e}"))).collect::<Result<_>>()?;
    if let Some(p) = &a.json {
        raylab_render::film::atomic::check_writable(p).map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    let threads = a.threads.map_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()), |t| t as usize);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    let scenes: Vec<Option<PathBuf>> = if a.scenes.is_empty() { vec![None] } else { a.scenes.iter().cloned().map(Some).collect() };
    let mut figures = Vec::new();
    pool.install(|| -> Result<()> {
        for path in &scenes {
            figures.push(bench_scene(a, path.as_ref(), &accels, &peer_kinds, &kinds, threads)?);
        }
        Ok(())
    })?;
    if let Some(p) = &a.json {
        let report = PeersReport {
            machine: Machine { cpu: cpu_name(), threads },
            raylab_version: env!("CARGO_PKG_VERSION").into(),
            repeats: a.repeats,
            resolution: a.resolution,
            tolerance: Tolerance { relative_t: agree::REL_T_TOLERANCE, disagreeing_per_ray: agree::DISAGREEING_PER_RAY },
            scenes: figures,
        };
        raylab_render::film::atomic::write_atomic(p, serde_json::to_string_pretty(&report)?).with_context(|| format!("{}: cannot write", p.display()))?;
        eprintln!("Wrote {}.", p.display());
    }
    Ok(())
}

/// Wide layouts copy the triangles into their leaf blocks and never read the mesh while
/// tracing; the others index into it, so its positions and indices count as theirs.
fn reads_mesh(k: AccelKind) -> bool {
    !matches!(k, AccelKind::Bvh8 | AccelKind::Bvh4 | AccelKind::Bvh8Sbvh | AccelKind::Bvh8Q)
}

fn bench_scene(a: &BenchArgs, path: Option<&PathBuf>, accels: &[AccelKind], peer_kinds: &[PeerKind], kinds: &[RayKind], threads: usize) -> Result<SceneFigures> {
    let name = path.map_or("default scene".to_string(), |p| p.display().to_string());
    let o = Overrides { accel: Some(AccelKind::Bvh), ..Default::default() };
    let scene = match path {
        Some(p) => raylab_loader::load_scene_or_mesh(p, &o)?,
        None => raylab_loader::default_scene(&o)?,
    };
    let prims = &scene.geometry;
    let tris: Vec<[Vec3; 3]> = (0..prims.len() as u32).map(|i| prims.triangle(i).ok_or(raylab_peers::PeerError::NotATriangle(i))).collect::<Result<_, _>>().with_context(|| name.clone())?;
    let mesh_bytes: usize = prims.meshes.iter().map(|m| m.positions.len() * 12 + m.indices.len() * 12).sum();
    let height = ((a.resolution as f64 * scene.settings.height as f64 / scene.settings.width as f64).round() as u32).max(1);
    let oracle_kind = if prims.len() <= a.oracle_limit { AccelKind::None } else { AccelKind::Bvh };
    let oracle = RaylabPeer { kind: oracle_kind, accel: AnyAccel::build(oracle_kind, prims, &BuildOptions::default()), prims, mesh_bytes: 0 };
    let mut sets = Vec::new();
    for s in rays::generate(&scene, a.resolution, height, kinds, a.seed) {
        let any_hit = s.kind.any_hit();
        let mut set = Set { name: s.kind.name().to_string(), any_hit, closest: vec![None; s.rays.len()], occluded: vec![false; s.rays.len()], rays: s.rays, packets: None };
        if any_hit {
            harness::occluded(&oracle, &set.rays, &mut set.occluded);
        } else {
            harness::closest(&oracle, &set.rays, &mut set.closest);
        }
        if s.kind == RayKind::Primary {
            // The lab's primary rays already come in 4×4 tiles (rays::tile_order, the order
            // TilePackets describes): the packets are consecutive ranges of them.
            let tiles = TilePackets::new(a.resolution, height);
            sets.push(Set { name: PACKETS.into(), any_hit: false, rays: set.rays.clone(), packets: Some(tiles.packets), closest: set.closest.clone(), occluded: Vec::new() });
        }
        sets.push(set);
    }
    sets.sort_by_key(|s| ["primary", "diffuse", "shadow", PACKETS].iter().position(|n| *n == s.name));
    drop(oracle);

    // Builds: the median of `repeats` builds, keeping the last structure.
    let mut built: Vec<(Box<dyn Peer + '_>, f64)> = Vec::new();
    for &k in accels {
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..a.repeats {
            let accel = AnyAccel::build(k, prims, &BuildOptions::default());
            times.push(accel.stats().build_ms);
            last = Some(accel);
        }
        let accel = last.unwrap();
        accel.validate(prims).with_context(|| format!("{name}: {k} failed validation"))?;
        let peer = RaylabPeer { kind: k, accel, prims, mesh_bytes: if reads_mesh(k) { mesh_bytes } else { 0 } };
        built.push((Box::new(peer), median(times)));
    }
    for &k in peer_kinds {
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..a.repeats {
            let peer = raylab_peers::build(k, &tris, threads)?;
            times.push(peer.build_ms());
            last = Some(peer);
        }
        built.push((last.unwrap(), median(times)));
    }

    // Traces: pass 0 is the warm-up; structures interleave within each pass.
    let mut timings: Vec<Vec<Vec<Timing>>> = vec![vec![Vec::new(); sets.len()]; built.len()];
    let mut agreements: Vec<Vec<Option<agree::Agreement>>> = vec![vec![None; sets.len()]; built.len()];
    for pass in 0..=a.repeats {
        for (i, (peer, _)) in built.iter().enumerate() {
            for (j, s) in sets.iter().enumerate() {
                let (t, agreement) = if s.any_hit {
                    let mut out = vec![false; s.rays.len()];
                    (harness::occluded(peer.as_ref(), &s.rays, &mut out), (pass == 0).then(|| agree::any(&s.occluded, &out)))
                } else {
                    let mut out = vec![None; s.rays.len()];
                    let t = match &s.packets {
                        Some(p) => harness::closest_packets(peer.as_ref(), &s.rays, p, &mut out),
                        None => harness::closest(peer.as_ref(), &s.rays, &mut out),
                    };
                    (t, (pass == 0).then(|| agree::closest(&s.closest, &out)))
                };
                if pass > 0 {
                    timings[i][j].push(t);
                } else {
                    agreements[i][j] = agreement;
                }
            }
        }
    }

    // Tables.
    let n = tris.len();
    println!("{name}: {n} triangles; {} threads; rays from a {}×{height} camera grid; oracle {oracle_kind}; median of {} passes", threads, a.resolution, a.repeats);
    println!("\n| structure | build ms | memory MiB | bytes/triangle |\n|---|---|---|---|");
    for (peer, build_ms) in &built {
        println!("| {} | {build_ms:.1} | {:.2} | {:.1} |", peer.name(), peer.memory_bytes() as f64 / (1 << 20) as f64, peer.memory_bytes() as f64 / n as f64);
    }
    let set_names: Vec<&str> = sets.iter().map(|s| s.name.as_str()).collect();
    let mut rows = Vec::new();
    for (i, (peer, _)) in built.iter().enumerate() {
        let speeds = sets
            .iter()
            .enumerate()
            .map(|(j, s)| {
                let count = s.rays.len() as f64 / 1e6;
                let wall = median(timings[i][j].iter().map(|t| t.wall_s).collect());
                let cpu = median(timings[i][j].iter().map(|t| t.cpu_s).collect());
                Some(Speed { mrays_wall: count / wall.max(1e-12), mrays_cpu: if cpu > 0.0 { count / cpu } else { 0.0 } })
            })
            .collect();
        rows.push(Row { structure: peer.name(), speeds });
    }
    println!("\nMrays/s per CPU second (ratio to {REFERENCE}):\n\n{}", table::speed_table(&set_names, &rows, REFERENCE, Clock::Cpu));
    println!("Mrays/s, wall clock (ratio to {REFERENCE}):\n\n{}", table::speed_table(&set_names, &rows, REFERENCE, Clock::Wall));
    let robust = rows.iter().find(|r| r.structure == ROBUST);
    if robust.is_some() {
        println!("Mrays/s per CPU second (ratio to {ROBUST}: Embree with the guarantees of raylab's kernels):\n\n{}", table::speed_table(&set_names, &rows, ROBUST, Clock::Cpu));
    }

    let reference = rows.iter().find(|r| r.structure == REFERENCE);
    let mut failures = Vec::new();
    let mut structures = Vec::new();
    for (i, ((peer, build_ms), r)) in built.iter().zip(&rows).enumerate() {
        let mut per_kind = BTreeMap::new();
        for (j, s) in sets.iter().enumerate() {
            let agreement = agreements[i][j].clone().unwrap();
            if agreement.disagreeing > 0 {
                println!("{}: {} of {} {} rays disagree with the oracle (allowed {}): first {}", peer.name(), agreement.disagreeing, agreement.rays, s.name, agreement.allowed(), agreement.first.as_deref().unwrap_or(""));
            }
            if !agreement.ok() {
                failures.push(format!("{} on {} rays: {} disagree, more than the {} allowed; first {}", peer.name(), s.name, agreement.disagreeing, agreement.allowed(), agreement.first.as_deref().unwrap_or("")));
            }
            let speed = r.speeds[j].unwrap();
            let ratio_to = |r: Option<&Row>| r.and_then(|x| x.speeds[j]).map(|base| table::ratio(speed, base));
            per_kind.insert(s.name.clone(), KindFigures { speed, ratio_to_embree: ratio_to(reference), ratio_to_embree_robust: ratio_to(robust), agreement });
        }
        structures.push(StructureFigures { name: peer.name(), build_ms: *build_ms, memory_bytes: peer.memory_bytes(), bytes_per_triangle: peer.memory_bytes() as f64 / n as f64, rays: per_kind });
    }
    if !failures.is_empty() {
        bail!("{name}: answers differ from the oracle beyond the tolerance (docs/performance.md):\n  {}", failures.join("\n  "));
    }
    Ok(SceneFigures { scene: name, triangles: n, oracle: oracle_kind.name().into(), structures })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The packets are ranges of the lab's primary rays: both must use the same tile order.
    #[test]
    fn packets_follow_the_lab_tile_order() {
        for (w, h) in [(6, 5), (16, 8), (7, 9)] {
            let lab: Vec<u32> = rays::tile_order(w, h).map(|(x, y)| y * w + x).collect();
            assert_eq!(TilePackets::new(w, h).order, lab, "{w}x{h}");
        }
    }
}
