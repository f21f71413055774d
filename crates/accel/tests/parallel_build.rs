//! Parallel builds are deterministic: the same tree, node for node, whatever the number
//! of threads (subtrees built by `rayon::join`, large nodes binned and partitioned in parallel).

use raylab_accel::bvh::{self, Bvh, SplitMethod};
use raylab_accel::{Accel, BuildOptions, Primitives, SphereBvh, WideBvh};
use raylab_testkit as kit;

fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}

fn same_tree(name: &str, a: &Bvh, b: &Bvh) {
    assert_eq!(a.indices, b.indices, "{name}: primitive order");
    assert!(a.nodes == b.nodes, "{name}: nodes differ");
}

/// The 69k-triangle bunny is large enough for the root's binning to run in parallel.
#[test]
fn builds_do_not_depend_on_the_thread_count() {
    let Some(path) = kit::shared_file("bunny_69451.obj") else { return };
    let soup = kit::read_obj_triangles(&path);
    assert!(soup.len() > 65_536);
    let opts = BuildOptions::default();
    type Builder = fn(&kit::Soup, &BuildOptions) -> Bvh;
    let builders: [(&str, Builder); 4] = [
        ("bvh", |s, o| Bvh::build(s, SplitMethod::BinnedSah, o)),
        ("sbvh", |s, o| bvh::sbvh::build(s, o)),
        ("lbvh", |s, o| bvh::lbvh::build(s, o)),
        ("lbvh-ploc", |s, o| bvh::ploc::build(s, o)),
    ];
    for (name, build) in builders {
        let one = on_threads(1, || build(&soup, &opts));
        one.validate(&soup).unwrap();
        // From 4 threads the binned SAH partitions its largest nodes in parallel.
        for threads in [2, 3, 4] {
            let many = on_threads(threads, || build(&soup, &opts));
            same_tree(&format!("{name} on {threads} threads"), &one, &many);
        }
        if name == "bvh" {
            let w1 = WideBvh::<8>::from_binary(&one, &soup, "bvh8");
            w1.validate(&soup).unwrap();
            for threads in [2, 4] {
                let w = on_threads(threads, || WideBvh::<8>::from_binary(&build(&soup, &opts), &soup, "bvh8"));
                assert!(w1.nodes == w.nodes && w1.blocks == w.blocks, "bvh8 differs on {threads} threads");
            }
        }
    }
}

/// The sphere BVH (PLOC over spheres, then the shared parallel flattening). Its nodes are
/// private: the debug listing (nodes, indices, primitive count) stands for them, and its
/// floats print exactly.
#[test]
fn sphere_bvh_does_not_depend_on_the_thread_count() {
    let Some(path) = kit::shared_file("bunny_69451.obj") else { return };
    let soup = kit::read_obj_triangles(&path);
    let opts = BuildOptions::default();
    let one = on_threads(1, || SphereBvh::build(&soup, &opts));
    one.validate(&soup).unwrap();
    let listing = format!("{one:?}");
    for threads in [2, 3] {
        let many = on_threads(threads, || SphereBvh::build(&soup, &opts));
        assert!(format!("{many:?}") == listing, "sphere-bvh differs on {threads} threads");
    }
}
