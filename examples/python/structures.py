"""Every acceleration structure over the bunny, one set of rays, checked against the oracle
with NumPy, and a plot of Mrays/s and nodes visited per ray (written to PNG).

    python examples/python/structures.py [mesh.obj] [-o structures.png] [--rays N]

Needs `pip install ./crates/python matplotlib`. The structure `none` tests every triangle
for every ray: it is the oracle, and (with `aabb`, one box per object) the slowest by far.
"""

import argparse
import pathlib
import statistics
import time

import numpy as np

import raylab
from diffuse_rays import diffuse_rays

HERE = pathlib.Path(__file__).resolve().parent
LINEAR = ("none", "aabb")
DEFAULT_MESH = HERE.parents[1].parent / "shared" / "scenes" / "bunny_69451.obj"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh", nargs="?", default=DEFAULT_MESH, type=pathlib.Path)
    ap.add_argument("-o", "--output", default="structures.png", type=pathlib.Path)
    ap.add_argument("--rays", default=10_000, type=int, help="diffuse rays from the surface (default 10000)")
    ap.add_argument("--repeats", default=3, type=int, help="timed passes after a warm-up; the median is plotted")
    a = ap.parse_args()

    vertices, indices = raylab.load_mesh(a.mesh)
    origins, directions = diffuse_rays(vertices, indices, a.rays)
    print(f"{a.mesh.name}: {len(indices)} triangles, {a.rays} diffuse rays")

    rows = []
    oracle = None
    for name in raylab.accels():  # "none", the oracle, comes first
        s = raylab.build(vertices, indices, accel=name)
        s.validate()
        hits = s.trace(origins, directions)  # warm-up, and the answers checked below
        times = []
        # The linear structures test every triangle: one timed pass is plenty (and minutes less).
        for _ in range(1 if name in LINEAR else a.repeats):
            t0 = time.perf_counter()
            s.trace(origins, directions)
            times.append(time.perf_counter() - t0)
        if oracle is None:
            oracle = hits
        # Same distances ray by ray, and the same rays hit (ties between two triangles at the
        # same t may name either, so the primitive ids are not compared).
        assert np.array_equal(hits["t"], oracle["t"]), f"{name}: distances differ from the oracle"
        assert np.array_equal(hits["prim"] >= 0, oracle["prim"] >= 0), f"{name}: hit set differs from the oracle"
        st = s.stats
        rows.append((name, a.rays / statistics.median(times) / 1e6, hits["nodes_visited"].mean(), hits["prim_tests"].mean(), st["build_ms"], st["memory_bytes"] / 1024))
    hit_rate = (oracle["prim"] >= 0).mean()
    print(f"all {len(rows)} structures agree with the oracle on every ray ({hit_rate:.1%} hit)")
    print(f"{'structure':<14} {'Mrays/s':>9} {'nodes/ray':>10} {'tests/ray':>10} {'build ms':>9} {'KiB':>9}")
    for r in rows:
        print(f"{r[0]:<14} {r[1]:>9.2f} {r[2]:>10.1f} {r[3]:>10.1f} {r[4]:>9.1f} {r[5]:>9.1f}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [r[0] for r in rows]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5), constrained_layout=True)
    ax1.bar(names, [r[1] for r in rows], color="tab:blue")
    ax1.set_ylabel("Mrays/s (median)")
    ax1.set_yscale("log")
    ax1.set_title(f"{a.mesh.name}: {a.rays} diffuse rays")
    ax2.bar(names, [r[2] for r in rows], color="tab:orange")
    ax2.set_ylabel("nodes visited per ray (mean)")
    ax2.set_yscale("log")
    ax2.set_title("traversal work")
    for ax in (ax1, ax2):
        ax.tick_params(axis="x", rotation=45)
    fig.savefig(a.output, dpi=120)
    print(f"Wrote {a.output}.")


if __name__ == "__main__":
    main()
