//! Traversal speed of every structure on the Stanford bunny (69k triangles) with two fixed,
//! seeded ray sets, as tinybvh's speed test separates them: coherent primary rays from a
//! pinhole camera, and incoherent rays between random points around the model.
//!
//! `cargo bench -p raylab-accel --bench traverse [-- FILTER]`; never run by the tests.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters};
use raylab_core::{Aabb, Pcg32, Ray, Vec3};
use raylab_testkit as kit;

const RAYS: usize = 16 * 1024;

/// A 128x128 pinhole camera looking at the model's centre from in front of it.
fn primary_rays(b: &Aabb) -> Vec<Ray> {
    let side = (RAYS as f32).sqrt() as usize;
    let eye = b.centroid() + Vec3::new(0.0, 0.0, 2.0 * b.extent().max_element());
    let half = 0.6 * b.extent().max_element();
    (0..side * side)
        .map(|k| {
            let (x, y) = ((k % side) as f32 + 0.5, (k / side) as f32 + 0.5);
            let target = b.centroid() + half * Vec3::new(2.0 * x / side as f32 - 1.0, 1.0 - 2.0 * y / side as f32, 0.0);
            Ray::new(eye, (target - eye).normalize())
        })
        .collect()
}

fn traverse(c: &mut Criterion) {
    let soup = kit::read_obj_triangles(&kit::shared_scenes().join("bunny_69451.obj"));
    let b = soup.bounds();
    let mut rng = Pcg32::new(2024, 1);
    let sets = [
        ("primary", primary_rays(&b)),
        ("incoherent", kit::random_rays(&mut rng, RAYS, &Aabb::new(b.min - b.extent(), b.max + b.extent()), &b)),
    ];
    let opts = BuildOptions::default();
    for &kind in AccelKind::ALL.iter().filter(|&&k| k != AccelKind::None) {
        let accel = AnyAccel::build(kind, &soup, &opts);
        println!("{}", accel.stats());
        for (set, rays) in &sets {
            let mut group = c.benchmark_group(*set);
            group.throughput(Throughput::Elements(rays.len() as u64));
            group.bench_function(BenchmarkId::new("intersect", kind), |bench| {
                bench.iter(|| {
                    let mut counters = Counters::default();
                    rays.iter().filter(|r| accel.intersect(&soup, r, &mut counters).is_some()).count()
                })
            });
            group.bench_function(BenchmarkId::new("occluded", kind), |bench| {
                bench.iter(|| {
                    let mut counters = Counters::default();
                    rays.iter().filter(|r| accel.occluded(&soup, r, &mut counters)).count()
                })
            });
            group.finish();
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = traverse
}
criterion_main!(benches);
