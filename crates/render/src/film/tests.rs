//! The film's promise: any split of a render (tiles, sample ranges, interruption and
//! resume, a trip through the file format) gives the same bits as one uninterrupted render.

use std::sync::atomic::{AtomicBool, Ordering};

use raylab_accel::BuildOptions;
use raylab_core::{Rgb, Transform, Vec3};

use super::*;
use crate::render::{film_header, render_tile, Control, Stop};
use crate::{Camera, IntegratorKind, Light, Material, RenderSettings, SamplerKind, Scene, Sphere};

/// Two diffuse spheres, one emitting, path traced with the random sampler: noisy, so any
/// change in summation order would show in the low bits. 7 spp in passes of 2: four
/// passes, the last of one sample.
fn scene() -> Scene {
    let camera = Camera::new(Vec3::new(0.0, 0.5, 4.0), Vec3::ZERO, Vec3::Y, 45.0, 4.0 / 3.0, 0.0, None).unwrap();
    let settings = RenderSettings { width: 37, height: 21, spp: 7, sampler: SamplerKind::Random, integrator: IntegratorKind::Path, max_depth: 4, seed: 5, ..Default::default() };
    let mut scene = Scene::new(camera, settings);
    let m = scene.add_material("grey", Material::Diffuse { albedo: Rgb::splat(0.6).into() });
    let sphere = |center, radius, emission| Sphere { center, radius, to_world: Transform::IDENTITY, material: m, emission };
    scene.geometry.add_sphere(sphere(Vec3::ZERO, 1.0, Rgb::ZERO));
    scene.geometry.add_sphere(sphere(Vec3::new(1.5, 1.5, 0.5), 0.4, Rgb::splat(8.0)));
    scene.lights.push(Light::Point { position: Vec3::new(-2.0, 3.0, 2.0), intensity: Rgb::splat(20.0) });
    scene.build_accel(&BuildOptions::default());
    scene
}

const PASS: u32 = 2;

fn never() -> AtomicBool {
    AtomicBool::new(false)
}

fn render(scene: &Scene, crop: Crop, samples: std::ops::Range<u32>) -> Film {
    let mut film = Film::new(film_header(scene, PASS), crop).unwrap();
    let cancel = never();
    let stop = render_tile(scene, &mut film, samples, &Control { cancel: &cancel, deadline: None, progress: &|_| {} }, |_| Ok::<(), FilmError>(())).unwrap();
    assert_eq!(stop, Stop::Done);
    film
}

fn bits(pixels: &[Rgb]) -> Vec<[u32; 3]> {
    pixels.iter().map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]).collect()
}

#[test]
fn tiles_sample_ranges_and_resumes_give_the_same_bits() {
    let scene = scene();
    let full = Crop::full(37, 21);
    let whole = render(&scene, full, 0..7);
    assert!(whole.is_complete());
    assert_eq!(whole.blocks().iter().map(|b| (b.first, b.count)).collect::<Vec<_>>(), vec![(0, 4)]);
    let reference = bits(&whole.resolve());
    // Not a trivially flat image: the comparison below would mean nothing.
    let mut distinct = reference.clone();
    distinct.sort();
    distinct.dedup();
    assert!(distinct.len() > 150, "{}", distinct.len());

    // Tiles: three bands, merged in reverse order.
    let tiles: Vec<Film> = (0..3).rev().map(|i| render(&scene, Crop::tile(37, 21, i, 3).unwrap(), 0..7)).collect();
    assert_eq!(bits(&Film::merge_all(tiles).unwrap().resolve()), reference, "tiles");

    // Sample ranges on pass boundaries, merged out of order.
    let ranges = vec![render(&scene, full, 6..7), render(&scene, full, 0..2), render(&scene, full, 2..6)];
    let merged = Film::merge_all(ranges).unwrap();
    assert_eq!(merged.blocks(), whole.blocks(), "the same blocks, bit for bit");
    assert_eq!(bits(&merged.resolve()), reference, "sample ranges");
    assert_eq!(merged.counters, whole.counters);

    // Tiles × sample ranges: a crop of two columns of pixels, split in samples too.
    let left = Crop { x0: 0, y0: 0, x1: 20, y1: 21 };
    let right = Crop { x0: 20, y0: 0, x1: 37, y1: 21 };
    let parts = vec![render(&scene, right, 0..7), render(&scene, left, 4..7), render(&scene, left, 0..4)];
    assert_eq!(bits(&Film::merge_all(parts).unwrap().resolve()), reference, "crops × ranges");

    // Interrupted after each pass in turn, saved, read back, resumed.
    for stop_after in 1..4 {
        let cancel = AtomicBool::new(false);
        let control = Control { cancel: &cancel, deadline: None, progress: &|_| {} };
        let mut film = Film::new(film_header(&scene, PASS), full).unwrap();
        let mut passes = 0;
        let stop = render_tile(&scene, &mut film, 0..7, &control, |_| {
            passes += 1;
            if passes == stop_after {
                cancel.store(true, Ordering::Relaxed);
            }
            Ok::<(), FilmError>(())
        })
        .unwrap();
        assert_eq!(stop, Stop::Cancelled);
        assert_eq!(film.passes(), 0..stop_after);
        let mut resumed = Film::from_bytes(&film.to_bytes()).unwrap();
        assert_eq!(resumed, film);
        let again = never();
        let stop = render_tile(&scene, &mut resumed, 0..7, &Control { cancel: &again, deadline: None, progress: &|_| {} }, |_| Ok::<(), FilmError>(())).unwrap();
        assert_eq!(stop, Stop::Done);
        assert_eq!(bits(&resumed.resolve()), reference, "resumed after {stop_after} passes");
    }
}

#[test]
fn the_plain_render_is_the_mean_of_the_samples() {
    // One pass per sample, f64 sums: the resolved pixel is the mean of the samples to f32
    // precision, as the render loop computed before the film.
    let scene = scene();
    let out = crate::render(&scene, &|_| {});
    assert_eq!(out.pixels.len(), 37 * 21);
    let one_pass = render(&scene, Crop::full(37, 21), 0..7).resolve();
    for (a, b) in out.pixels.iter().zip(&one_pass) {
        assert!((*a - *b).abs().max_element() <= 1e-5 * a.max_element().max(1.0), "{a} vs {b}");
    }
}

fn header() -> FilmHeader {
    FilmHeader { width: 4, height: 2, spp: 5, pass_samples: 1, scene_hash: 1, settings_hash: 2, version: "test".into(), heatmap: false }
}

fn one_pixel_pass(v: f64) -> Vec<f64> {
    vec![v, v, v, v * v]
}

#[test]
fn blocks_are_the_binary_counter_of_the_passes() {
    let crop = Crop { x0: 1, y0: 1, x1: 2, y1: 2 };
    let mut film = Film::new(header(), crop).unwrap();
    let shape = |f: &Film| f.blocks().iter().map(|b| (b.first, b.count)).collect::<Vec<_>>();
    let mut seen = Vec::new();
    for (p, v) in [1.0, 3.0, 0.5, 0.25, 2.0].into_iter().enumerate() {
        film.add_pass(p as u32, one_pixel_pass(v), &Counters::default(), 0).unwrap();
        seen.push(shape(&film));
    }
    assert_eq!(seen, vec![vec![(0, 1)], vec![(0, 2)], vec![(0, 2), (2, 1)], vec![(0, 4)], vec![(0, 4), (4, 1)]]);
    // ((1 + 3) + (0.5 + 0.25)) + 2 = 6.75 over 5 samples.
    assert_eq!(film.resolve(), vec![Rgb::splat(1.35)]);
    // Luminance samples 1, 3, 0.5, 0.25, 2: mean 1.35, sample variance 1.2125, over n = 5.
    let expected = (1.0f64 + 9.0 + 0.25 + 0.0625 + 4.0 - 6.75 * 6.75 / 5.0) / 4.0 / 5.0;
    assert!((film.variance()[0] as f64 - expected).abs() < 1e-6, "{} vs {expected}", film.variance()[0]);
    assert_eq!(film.add_pass(7, one_pixel_pass(1.0), &Counters::default(), 0).unwrap_err().to_string(), "pass 7 does not follow the passes 0..5 held (of 5)");
}

#[test]
fn bad_merges_and_ranges_are_refused() {
    let h = header();
    let full = Crop::full(4, 2);
    let pass = |crop: Crop, p: u32| {
        let mut f = Film::new(h.clone(), crop).unwrap();
        f.add_pass(p, vec![0.5; crop.pixels() * CHANNELS], &Counters::default(), 0).unwrap();
        f
    };
    let e = Film::merge_all(vec![pass(full, 0), pass(full, 0)]).unwrap_err();
    assert_eq!(e.to_string(), "cannot merge: crop 0,0,4,2: samples 0..1 and 0..1 overlap: samples would be counted twice");
    let e = Film::merge_all(vec![pass(full, 0), pass(full, 2)]).unwrap_err();
    assert_eq!(e.to_string(), "cannot merge: crop 0,0,4,2: samples 0..1 and 2..3 leave a gap");
    let top = Crop { x0: 0, y0: 0, x1: 4, y1: 1 };
    let e = Film::merge_all(vec![pass(top, 0), pass(Crop { x0: 1, y0: 0, x1: 4, y1: 2 }, 0)]).unwrap_err();
    assert_eq!(e.to_string(), "cannot merge: crops 0,0,4,1 and 1,0,4,2 overlap: a pixel would be counted twice");
    let e = Film::merge_all(vec![pass(top, 0), pass(Crop { x0: 1, y0: 1, x1: 4, y1: 2 }, 0)]).unwrap_err();
    assert_eq!(e.to_string(), "cannot merge: the crops leave 1 pixels of 0,0,4,2 uncovered");
    let mut other = pass(full, 1);
    other.header.scene_hash = 9;
    let e = Film::merge_all(vec![pass(full, 0), other]).unwrap_err();
    assert_eq!(e.to_string(), "cannot merge: part 2 does not match part 1: it is of another scene (scene hash 0000000000000009, expected 0000000000000001)");
    let h2 = FilmHeader { spp: 64, pass_samples: 16, ..h.clone() };
    assert_eq!(h2.passes_of(&(16..64)).unwrap(), 1..4);
    assert_eq!(h2.passes_of(&(8..64)).unwrap_err().to_string(), "samples 8..64 must be a non-empty range within 0..64 starting and ending on a multiple of the pass size 16");
    assert_eq!(Crop::tile(4, 2, 2, 2).unwrap_err().to_string(), "tile 2/2: the index must be below the count (tiles are numbered from 0)");
    assert_eq!(Crop::tile(4, 2, 0, 3).unwrap_err().to_string(), "tile 0/3: the image has only 2 rows, so at most 2 tiles");
    let bands: Vec<Crop> = (0..3).map(|i| Crop::tile(10, 7, i, 3).unwrap()).collect();
    assert_eq!(bands.iter().map(|c| (c.y0, c.y1)).collect::<Vec<_>>(), vec![(0, 2), (2, 4), (4, 7)]);
}

#[test]
fn corrupt_film_files_are_refused_without_allocating() {
    let mut film = Film::new(header(), Crop::full(4, 2)).unwrap();
    film.add_pass(0, vec![0.25; 8 * CHANNELS], &Counters { rays: 8, ..Default::default() }, 1).unwrap();
    let bytes = film.to_bytes();
    assert_eq!(Film::from_bytes(&bytes).unwrap(), film);
    let e = |b: &[u8]| Film::from_bytes(b).unwrap_err().to_string();
    assert_eq!(e(b"PNG"), "not a raylab film: wrong magic bytes (expected RAYLABFM)");
    assert_eq!(e(&bytes[..bytes.len() - 1]), "not a raylab film: checksum mismatch: the file is truncated or damaged");
    let mut flipped = bytes.clone();
    flipped[100] ^= 1;
    assert_eq!(e(&flipped), "not a raylab film: checksum mismatch: the file is truncated or damaged");
    // A header announcing a huge crop, with a valid checksum: refused by the size check.
    let mut huge = bytes[..bytes.len() - 8].to_vec();
    let crop_at = 8 + 4 * 5 + 1 + 16 + 2 + "test".len();
    huge[crop_at + 8..crop_at + 16].copy_from_slice(&[0xff, 0xff, 0, 0, 0xff, 0xff, 0, 0]);
    huge[12..20].copy_from_slice(&[0xff, 0xff, 0, 0, 0xff, 0xff, 0, 0]);
    let mut sum = codec::Fnv64::default();
    sum.update(&huge);
    huge.extend_from_slice(&sum.0.to_le_bytes());
    assert_eq!(e(&huge), format!("not a raylab film: the header announces 1 blocks of {} pixels ({} bytes) but {} bytes follow", 65535u64 * 65535, (65535u64 * 65535 * 32 + 8), 8 + 8 * 32));
    let mut old = bytes.clone();
    old[8] = 9;
    assert_eq!(e(&old), "not a raylab film: film format version 9, this raylab reads version 1");
}

#[test]
fn the_plain_render_of_no_samples_is_black_not_a_panic() {
    let mut scene = scene();
    scene.settings.spp = 0;
    let out = crate::render(&scene, &|_| {});
    assert_eq!(out.pixels, vec![Rgb::ZERO; 37 * 21]);
}

/// FNV-1a, 64 bit, from its definition: offset basis 0xcbf29ce484222325, each byte XORed in,
/// then multiplied by the prime 2^40 + 2^8 + 0xb3, modulo 2^64.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3))
}

/// A film file written byte by byte from the layout in `codec.rs`: `header()` (4 × 2, 5 spp in
/// passes of 1, hashes 1 and 2, version "test", no heat map), the crop 1,1,2,2 (one pixel),
/// 3 non-finite samples, counters 10, 20, 30, 40, the block count `count`, the blocks
/// (`first`, `n`) with the pixel's sums (first, n, 0.5, 0.25), and the checksum.
fn film_file(count: u32, blocks: &[(u32, u32)]) -> Vec<u8> {
    let mut b = b"RAYLABFM".to_vec();
    for v in [1u32, 4, 2, 5, 1] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.push(0);
    b.extend_from_slice(&1u64.to_le_bytes());
    b.extend_from_slice(&2u64.to_le_bytes());
    b.extend_from_slice(&[4, 0]);
    b.extend_from_slice(b"test");
    for v in [1u32, 1, 2, 2] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [3u64, 10, 20, 30, 40] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&count.to_le_bytes());
    for &(first, n) in blocks {
        b.extend_from_slice(&first.to_le_bytes());
        b.extend_from_slice(&n.to_le_bytes());
        for v in [first as f64, n as f64, 0.5, 0.25] {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    let sum = fnv1a(&b);
    b.extend_from_slice(&sum.to_le_bytes());
    b
}

#[test]
fn fnv1a_matches_the_published_test_vectors() {
    // From the FNV reference test suite (Noll): "" is the offset basis, then "a" and "foobar".
    for (s, want) in [("", 0xcbf2_9ce4_8422_2325u64), ("a", 0xaf63_dc4c_8601_ec8c), ("foobar", 0x8594_4171_f739_67e8)] {
        let mut h = codec::Fnv64::default();
        h.update(s.as_bytes());
        assert_eq!(h.0, want, "{s:?}");
        let mut w = codec::Fnv64::default();
        std::fmt::Write::write_str(&mut w, s).unwrap();
        assert_eq!(w.0, want, "{s:?} through fmt::Write");
        assert_eq!(fnv1a(s.as_bytes()), want);
    }
}

#[test]
fn film_files_written_by_hand_are_read_and_written_back() {
    for blocks in [vec![(0, 4), (4, 1)], vec![(0, 2), (2, 1)], vec![(2, 2)], vec![(4, 1)]] {
        let bytes = film_file(blocks.len() as u32, &blocks);
        let film = Film::from_bytes(&bytes).unwrap();
        assert_eq!(film.header, header());
        assert_eq!(film.crop, Crop { x0: 1, y0: 1, x1: 2, y1: 2 });
        assert_eq!(film.nonfinite_samples, 3);
        assert_eq!(film.counters, Counters { rays: 10, nodes_visited: 20, prim_tests: 30, object_tests: 40 });
        let want: Vec<Block> = blocks.iter().map(|&(first, count)| Block { first, count, sums: vec![first as f64, count as f64, 0.5, 0.25] }).collect();
        assert_eq!(film.blocks(), &want[..]);
        assert_eq!(film.to_bytes(), bytes, "{blocks:?}");
    }
}

#[test]
fn film_files_with_bad_sizes_or_blocks_are_refused() {
    let e = |b: &[u8]| Film::from_bytes(b).unwrap_err().to_string();
    let not_aligned = |s: &str| format!("not a raylab film: block of passes {s} is not an aligned block following the previous one (of 5 passes)");
    // Blocks of 3 passes, at an odd start, past the 5 passes, after a gap.
    assert_eq!(e(&film_file(1, &[(0, 3)])), not_aligned("0+3"));
    assert_eq!(e(&film_file(1, &[(1, 2)])), not_aligned("1+2"));
    assert_eq!(e(&film_file(1, &[(4, 2)])), not_aligned("4+2"));
    assert_eq!(e(&film_file(2, &[(0, 2), (3, 1)])), not_aligned("3+1"));
    assert_eq!(e(&film_file(2, &[(0, 1), (1, 1)])), "not a raylab film: its blocks are not the maximal blocks of their passes");
    // 64 blocks is the most a header may announce (then their 64 × 40 bytes must follow).
    assert_eq!(e(&film_file(64, &[])), "not a raylab film: the header announces 64 blocks of 1 pixels (2560 bytes) but 0 bytes follow");
    assert_eq!(e(&film_file(65, &[])), "not a raylab film: 65 blocks (at most 64)");
    // The magic alone is truncated; 20 bytes hold the magic, the format version and a wrong checksum.
    assert_eq!(e(b"RAYLABFM"), "not a raylab film: truncated (8 bytes)");
    assert_eq!(e(b"RAYLABFM\x01\x00\x00\x00"), "not a raylab film: truncated (12 bytes)");
    // 16 bytes are the magic and a checksum, with no format version between them.
    assert_eq!(e(b"RAYLABFM\x01\x00\x00\x00\x00\x00\x00\x00"), "not a raylab film: truncated at byte 8");
    assert_eq!(e(b"RAYLABFM\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00"), "not a raylab film: checksum mismatch: the file is truncated or damaged");
    assert_eq!(e(b"RAYLABF"), "not a raylab film: wrong magic bytes (expected RAYLABFM)");
    assert_eq!(e(b"RAYLABFX\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00"), "not a raylab film: wrong magic bytes (expected RAYLABFM)");
}

#[test]
fn crops_by_hand() {
    let c = Crop { x0: 1, y0: 2, x1: 4, y1: 7 };
    assert_eq!((c.width(), c.height(), c.pixels()), (3, 5, 15));
    assert_eq!(c.to_string(), "1,2,4,7");
    assert_eq!(Crop::full(6, 8), Crop { x0: 0, y0: 0, x1: 6, y1: 8 });
    // Inside a 4 × 7 image (touching its right and bottom edges), not inside 3 × 7 or 4 × 6.
    assert_eq!(c.check(4, 7), Ok(()));
    let refused = |c: Crop, w: u32, h: u32| c.check(w, h).unwrap_err().to_string() == format!("crop {c} is empty or outside the {w}×{h} image");
    assert!(refused(c, 3, 7) && refused(c, 4, 6));
    assert!(refused(Crop { x0: 2, x1: 2, ..c }, 4, 7) && refused(Crop { y0: 7, y1: 7, ..c }, 4, 7));
    assert!(refused(Crop { x0: 3, x1: 2, ..c }, 4, 7) && refused(Crop { y0: 7, y1: 6, ..c }, 4, 7));
    // Overlap: crops sharing only an edge do not; moving one to each side in turn.
    let a = Crop { x0: 2, y0: 2, x1: 4, y1: 4 };
    for (b, overlap) in [
        (Crop { x0: 3, y0: 3, x1: 5, y1: 5 }, true),
        (Crop { x0: 1, y0: 1, x1: 3, y1: 3 }, true),
        (Crop { x0: 0, y0: 0, x1: 9, y1: 9 }, true),
        (Crop { x0: 4, y0: 2, x1: 6, y1: 4 }, false),
        (Crop { x0: 0, y0: 2, x1: 2, y1: 4 }, false),
        (Crop { x0: 2, y0: 4, x1: 4, y1: 6 }, false),
        (Crop { x0: 2, y0: 0, x1: 4, y1: 2 }, false),
    ] {
        assert_eq!((a.overlaps(&b), b.overlaps(&a)), (overlap, overlap), "{a} and {b}");
    }
    // Tiles: row(i) = ⌊i·h/count⌋, so 7 rows in 3 tiles are 0..2, 2..4, 4..7, and 2 rows make
    // at most 2 tiles of one row each.
    assert_eq!(Crop::tile(5, 7, 1, 3), Ok(Crop { x0: 0, y0: 2, x1: 5, y1: 4 }));
    assert_eq!(Crop::tile(5, 7, 2, 3), Ok(Crop { x0: 0, y0: 4, x1: 5, y1: 7 }));
    assert_eq!(Crop::tile(4, 2, 1, 2), Ok(Crop { x0: 0, y0: 1, x1: 4, y1: 2 }));
    assert_eq!(Crop::tile(4, 9, 0, 1), Ok(Crop::full(4, 9)));
    assert!(Crop::tile(4, 2, 0, 0).is_err());
}

/// 10 spp in passes of 4: passes 0..4, 4..8, 8..10.
fn header_10_by_4() -> FilmHeader {
    FilmHeader { spp: 10, pass_samples: 4, ..header() }
}

#[test]
fn pass_ranges_by_hand() {
    let h = header_10_by_4();
    assert_eq!(h.passes(), 3);
    assert_eq!((h.pass_range(0), h.pass_range(1), h.pass_range(2)), (0..4, 4..8, 8..10));
    assert_eq!(h.passes_of(&(0..10)), Ok(0..3));
    assert_eq!(h.passes_of(&(4..8)), Ok(1..2));
    assert_eq!(h.passes_of(&(4..10)), Ok(1..3));
    assert_eq!(h.passes_of(&(8..10)), Ok(2..3));
    assert_eq!(h.passes_of(&(0..4)), Ok(0..1));
    for bad in [4..4, std::ops::Range { start: 8, end: 4 }, 3..8, 4..9, 4..12, 12..16] {
        assert_eq!(h.passes_of(&bad).unwrap_err().to_string(), format!("samples {}..{} must be a non-empty range within 0..10 starting and ending on a multiple of the pass size 4", bad.start, bad.end), "{bad:?}");
    }
    let zero = FilmHeader { pass_samples: 0, ..h.clone() };
    assert_eq!(zero.passes_of(&(0..10)).unwrap_err().to_string(), "the pass size must be at least 1 sample");
    // Blocks: (0, 2) and (2, 2) are siblings, (2, 2) and (4, 2) are not (2 is not a multiple
    // of 4), nor blocks of different sizes, nor blocks with a gap.
    let b = |first, count| Block { first, count, sums: vec![] };
    assert!(b(0, 2).is_left_sibling_of(&b(2, 2)));
    assert!(b(8, 4).is_left_sibling_of(&b(12, 4)));
    assert!(!b(2, 2).is_left_sibling_of(&b(4, 2)));
    assert!(!b(4, 4).is_left_sibling_of(&b(8, 4)));
    assert!(!b(0, 2).is_left_sibling_of(&b(2, 1)));
    assert!(!b(0, 1).is_left_sibling_of(&b(2, 1)));
    assert_eq!(b(8, 4).end(), 12);
}

#[test]
fn header_mismatches_name_what_differs() {
    let h = header();
    assert_eq!(h.mismatch(&h.clone()), None);
    let other = FilmHeader { version: "old".into(), ..h.clone() };
    assert_eq!(h.mismatch(&other).unwrap(), "it was rendered by raylab old, this is raylab test");
    let other = FilmHeader { scene_hash: 0xab, ..h.clone() };
    assert_eq!(h.mismatch(&other).unwrap(), "it is of another scene (scene hash 00000000000000ab, expected 0000000000000001)");
    let settings = |o: &FilmHeader| format!("it has other render settings ({}×{}, {} spp in passes of {}, settings hash {:016x}; expected 4×2, 5 spp in passes of 1, settings hash 0000000000000002)", o.width, o.height, o.spp, o.pass_samples, o.settings_hash);
    for other in [
        FilmHeader { settings_hash: 3, ..h.clone() },
        FilmHeader { width: 5, ..h.clone() },
        FilmHeader { height: 3, ..h.clone() },
        FilmHeader { spp: 6, ..h.clone() },
        FilmHeader { pass_samples: 2, ..h.clone() },
        FilmHeader { heatmap: true, ..h.clone() },
    ] {
        assert_eq!(h.mismatch(&other).unwrap(), settings(&other), "{other:?}");
    }
}

/// One pass of a crop, pixel i holding the sums (i + 1)·(1, 2, 4)·`scale` and luminance² `l2`.
fn pass_sums(crop: Crop, scale: f64, l2: f64) -> Vec<f64> {
    (0..crop.pixels()).flat_map(|i| {
        let v = (i + 1) as f64 * scale;
        [v, 2.0 * v, 4.0 * v, l2]
    }).collect()
}

#[test]
fn films_hold_pass_ranges_and_accumulate_counts() {
    let h = header_10_by_4();
    let full = Crop::full(4, 2);
    let mut f = Film::new(h.clone(), full).unwrap();
    assert_eq!((f.passes(), f.samples(), f.is_complete()), (0..0, 0..0, false));
    f.add_pass(0, pass_sums(full, 1.0, 0.0), &Counters { rays: 5, ..Default::default() }, 1).unwrap();
    f.add_pass(1, pass_sums(full, 1.0, 0.0), &Counters { rays: 7, ..Default::default() }, 2).unwrap();
    assert_eq!((f.passes(), f.samples(), f.is_complete()), (0..2, 0..8, false));
    assert_eq!((f.counters.rays, f.nonfinite_samples), (12, 3));
    assert_eq!(f.add_pass(3, pass_sums(full, 1.0, 0.0), &Counters::default(), 0).unwrap_err().to_string(), "pass 3 does not follow the passes 0..2 held (of 3)");
    assert_eq!(f.add_pass(1, pass_sums(full, 1.0, 0.0), &Counters::default(), 0).unwrap_err().to_string(), "pass 1 does not follow the passes 0..2 held (of 3)");
    assert_eq!(f.add_pass(2, vec![0.0; 4], &Counters::default(), 0).unwrap_err().to_string(), "pass 2: 4 values for 8 pixels");
    f.add_pass(2, pass_sums(full, 1.0, 0.0), &Counters::default(), 0).unwrap();
    assert_eq!((f.passes(), f.samples(), f.is_complete()), (0..3, 0..10, true));
    // A film may start at any pass: passes 1 and 2 are samples 4..10, not the whole image.
    let mut late = Film::new(h.clone(), full).unwrap();
    late.add_pass(1, pass_sums(full, 1.0, 0.0), &Counters::default(), 0).unwrap();
    late.add_pass(2, pass_sums(full, 1.0, 0.0), &Counters::default(), 0).unwrap();
    assert_eq!((late.passes(), late.samples(), late.is_complete()), (1..3, 4..10, false));
    // Every pass of a crop is not the whole image either.
    let top = Crop { x0: 0, y0: 0, x1: 4, y1: 1 };
    let mut part = Film::new(h, top).unwrap();
    for p in 0..3 {
        part.add_pass(p, pass_sums(top, 1.0, 0.0), &Counters::default(), 0).unwrap();
    }
    assert_eq!((part.samples(), part.is_complete()), (0..10, false));
}

#[test]
fn merged_crops_land_in_their_pixels_and_sample_ranges_join_in_any_order() {
    // A 4 × 2 image, 5 passes of one sample. Crops (1,1)-(2,2) and (2,1)-(4,2), pass 0 each:
    // their bounding box is (1,1)-(4,2), three pixels holding 1, then 1 and 2 times (1, 2, 4).
    let h = header();
    let (a, b) = (Crop { x0: 1, y0: 1, x1: 2, y1: 2 }, Crop { x0: 2, y0: 1, x1: 4, y1: 2 });
    let film = |crop: Crop, pass: u32, scale: f64, rays: u64| {
        let mut f = Film::new(h.clone(), crop).unwrap();
        f.add_pass(pass, pass_sums(crop, scale, 0.0), &Counters { rays, ..Default::default() }, rays).unwrap();
        f
    };
    let m = Film::merge_all(vec![film(b, 0, 1.0, 2), film(a, 0, 10.0, 1)]).unwrap();
    assert_eq!(m.crop, Crop { x0: 1, y0: 1, x1: 4, y1: 2 });
    assert_eq!(m.resolve(), vec![Rgb::new(10.0, 20.0, 40.0), Rgb::new(1.0, 2.0, 4.0), Rgb::new(2.0, 4.0, 8.0)]);
    assert_eq!((m.counters.rays, m.nonfinite_samples), (3, 3));
    // Two rows: (0,0)-(2,1) above (0,1)-(2,2).
    let (top, bottom) = (Crop { x0: 0, y0: 0, x1: 2, y1: 1 }, Crop { x0: 0, y0: 1, x1: 2, y1: 2 });
    let m = Film::merge_all(vec![film(bottom, 0, 10.0, 0), film(top, 0, 1.0, 0)]).unwrap();
    assert_eq!(m.crop, Crop { x0: 0, y0: 0, x1: 2, y1: 2 });
    assert_eq!(m.resolve().iter().map(|p| p.x).collect::<Vec<_>>(), vec![1.0, 2.0, 10.0, 20.0]);
    // Passes 0, 1, 2 and 3, 4 of one crop, given out of order: the mean of 1, 2, 3, 4, 5 times
    // (1, 2, 4) is 3 times it; the counts add up.
    let parts = vec![film(a, 3, 4.0, 4), film(a, 1, 2.0, 2), film(a, 0, 1.0, 1), film(a, 4, 5.0, 5), film(a, 2, 3.0, 3)];
    let m = Film::merge_all(parts).unwrap();
    assert_eq!((m.passes(), m.counters.rays, m.nonfinite_samples), (0..5, 15, 15));
    assert_eq!(m.blocks().iter().map(|b| (b.first, b.count)).collect::<Vec<_>>(), vec![(0, 4), (4, 1)]);
    assert_eq!(m.resolve(), vec![Rgb::new(3.0, 6.0, 12.0)]);
    // Crops holding different passes are refused, and so is nothing.
    let e = Film::merge_all(vec![film(a, 0, 1.0, 0), film(b, 1, 1.0, 0)]).unwrap_err();
    assert_eq!(e.to_string(), "cannot merge: crop 2,1,4,2 holds samples 1..2, crop 1,1,2,2 holds 0..1");
    assert_eq!(Film::merge_all(vec![]).unwrap_err().to_string(), "nothing to merge");
    let e = Film::merge_all(vec![film(a, 0, 1.0, 0), Film::new(h.clone(), b).unwrap()]).unwrap_err();
    assert_eq!(e.to_string(), "cannot merge: part 2 holds no samples");
}

#[test]
fn resolve_and_variance_by_hand() {
    // Rec. 709: 0.2126 + 2·0.7152 + 4·0.0722 = 1.9318.
    assert!((luminance(1.0, 2.0, 4.0) - 1.9318).abs() < 1e-12);
    assert!((luminance(1.0, 0.0, 0.0) - 0.2126).abs() < 1e-12 && (luminance(0.0, 1.0, 0.0) - 0.7152).abs() < 1e-12 && (luminance(0.0, 0.0, 1.0) - 0.0722).abs() < 1e-12);
    // Two pixels, three passes of one sample: pixel i's samples are (i+1)·(1, 2, 4)·s for
    // s = 1, 2, 3, so luminances (i+1)·1.9318·s, with the squares summed as given.
    let h = FilmHeader { spp: 3, ..header() };
    let crop = Crop { x0: 0, y0: 0, x1: 2, y1: 1 };
    let mut f = Film::new(h, crop).unwrap();
    // One sample: no variance, even where the squared luminance (5) is not the square of the
    // luminance (1), which would divide 5 − 1 by n − 1 = 0.
    f.add_pass(0, vec![1.0, 1.0, 1.0, 5.0, 0.0, 0.0, 0.0, 0.0], &Counters::default(), 0).unwrap();
    assert_eq!(f.variance(), vec![0.0, 0.0]);
    let mut f = Film::new(FilmHeader { spp: 3, ..header() }, crop).unwrap();
    for s in 1..=3 {
        let sums: Vec<f64> = (0..2).flat_map(|i| {
            let v = (i + 1) as f64 * s as f64;
            let l = v * 1.9318;
            [v, 2.0 * v, 4.0 * v, l * l]
        }).collect();
        f.add_pass(s - 1, sums, &Counters::default(), 0).unwrap();
        if s == 2 {
            // Pixel 0's luminances 1.9318 and 3.8636: sample variance 1.9318²/2, over n = 2.
            let want = 1.9318f64 * 1.9318 / 2.0 / 2.0;
            assert!((f.variance()[0] as f64 - want).abs() < 1e-5 * want, "{}", f.variance()[0]);
        }
    }
    // Means: pixel 0 (2, 4, 8), pixel 1 (4, 8, 16).
    assert_eq!(f.resolve(), vec![Rgb::new(2.0, 4.0, 8.0), Rgb::new(4.0, 8.0, 16.0)]);
    // Sample variance of (1, 2, 3)·k is k², over n = 3: k = 1.9318 and 2·1.9318.
    let v = f.variance();
    for (i, k) in [1.9318f64, 2.0 * 1.9318].into_iter().enumerate() {
        assert!((v[i] as f64 - k * k / 3.0).abs() < 1e-5 * k * k, "pixel {i}: {}", v[i]);
    }
    // The heat map is colourised only on the whole frame: a crop of a heat-map film resolves to
    // its means.
    let mut hm = Film::new(FilmHeader { spp: 1, heatmap: true, ..header() }, crop).unwrap();
    hm.add_pass(0, vec![3.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0], &Counters::default(), 0).unwrap();
    assert_eq!(hm.resolve(), vec![Rgb::new(3.0, 0.0, 0.0), Rgb::new(5.0, 0.0, 0.0)]);
}
