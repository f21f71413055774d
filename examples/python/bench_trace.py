"""Tracing from NumPy against `raylab trace` on the same rays: 10^6 diffuse rays on the bunny
(a benchmark, not a test; run it on a quiet machine).

    python examples/python/bench_trace.py [--rays 1000000] [--accel bvh] [--raylab target/release/raylab]

Both sides build the same structure once, make one warm-up pass and report the median of
`--repeats` timed passes over the same rays, in `--rounds` that alternate between them; Python's time includes writing the per-ray
arrays (t, prim, u, v, nodes visited, primitive tests) that the CLI does not produce.
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import tempfile
import time

import numpy as np

import raylab
from diffuse_rays import diffuse_rays

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[1]
BUNNY = REPO.parent / "shared" / "scenes" / "bunny_69451.obj"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--accel", default="bvh")
    ap.add_argument("--repeats", type=int, default=3, help="timed passes per round, after a warm-up")
    ap.add_argument("--rounds", type=int, default=2, help="alternating CLI / NumPy rounds")
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--raylab", default=str(REPO / "target" / "release" / "raylab"), help="the CLI binary")
    ap.add_argument("--mesh", type=pathlib.Path, default=BUNNY)
    a = ap.parse_args()

    vertices, indices = raylab.load_mesh(a.mesh)
    o, d = diffuse_rays(vertices, indices, a.rays)
    s = raylab.build(a.mesh, accel=a.accel, threads=a.threads)
    with tempfile.TemporaryDirectory() as tmp:
        path = pathlib.Path(tmp) / "diffuse.rays"
        raylab.write_rays(path, o, d)
        threads = ["--threads", str(a.threads)] if a.threads else []
        s.trace(o, d, threads=a.threads)  # warm-up
        # Rounds alternate CLI and NumPy so that a busy machine slows both alike.
        cli_rates, py_rates, hits = [], [], None
        for _ in range(a.rounds):
            r = subprocess.run([a.raylab, "trace", str(a.mesh), "--rays", str(path), "--accel", a.accel, "--repeats", str(a.repeats), "--json", *threads], capture_output=True, text=True, check=True)
            cli = json.loads(r.stdout)
            cli_rates.append(cli["mrays_per_s"])
            times = []
            for _ in range(a.repeats):
                t0 = time.perf_counter()
                hits = s.trace(o, d, threads=a.threads)
                times.append(time.perf_counter() - t0)
            py_rates.append(a.rays / statistics.median(times) / 1e6)
    cli_mrays, py_mrays = statistics.median(cli_rates), statistics.median(py_rates)
    n_hits = int((hits["prim"] >= 0).sum())
    assert n_hits == cli["hits"], f"hits differ: Python {n_hits}, CLI {cli['hits']}"
    print(f"{a.mesh.name}, {a.rays} diffuse rays, {a.accel}, {cli['threads']} threads, medians of {a.repeats} passes over {a.rounds} alternating rounds")
    print(f"  raylab trace  {cli_mrays:8.2f} Mrays/s  {['%.2f' % x for x in cli_rates]}")
    print(f"  NumPy         {py_mrays:8.2f} Mrays/s  {['%.2f' % x for x in py_rates]}")
    print(f"  ratio NumPy / CLI = {py_mrays / cli_mrays:.3f}   ({n_hits} hits on both sides)")


if __name__ == "__main__":
    main()
