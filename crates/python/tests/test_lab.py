"""bench, compare and converge return the JSON schema's plain dicts."""

import json

import numpy as np
import pytest

import raylab
from conftest import run_cli


def test_bench_dict_matches_the_cli_schema_and_answers(cli, repo, tmp_path):
    scene = repo / "scenes/cube.toml"
    r = raylab.bench([scene], accels=["bvh", "kdtree", "none"], resolution=32, repeats=1)
    out = tmp_path / "b.json"
    c = run_cli(cli, "bench", scene, "--accels", "bvh,kdtree,none", "--resolution", "32", "--repeats", "1", "--json", out)
    assert c.returncode == 0, c.stderr
    cli_report = json.loads(out.read_text())
    assert set(r) == set(cli_report) == {"machine", "raylab_version", "repeats", "resolution", "results", "settings", "jobs"}
    assert r["jobs"]["ran"] == cli_report["jobs"]["ran"] == list(range(9))
    assert [x["accel"] for x in r["results"]] == ["bvh", "kdtree", "none"]
    for mine, theirs in zip(r["results"], cli_report["results"]):
        assert set(mine) == set(theirs)
        assert set(mine["stats"]) == set(theirs["stats"])
        for kind in ("primary", "diffuse", "shadow"):
            # The same rays (same seed) and the same answers as the CLI.
            for k in ("count", "hits", "t_sum", "node_visits_per_ray", "prim_tests_per_ray"):
                assert mine["rays"][kind][k] == theirs["rays"][kind][k], (mine["accel"], kind, k)
    assert r["results"][0]["rays"]["primary"]["count"] == 32 * 24


def test_bench_bad_names():
    with pytest.raises(ValueError, match=r"^rays: unknown ray kind `secondary` \(valid: primary, diffuse, shadow\)$"):
        raylab.bench(rays="primary,secondary")
    with pytest.raises(ValueError, match=r"^accels: unknown acceleration structure `octree`"):
        raylab.bench(accels=["bvh", "octree"])


def test_compare_by_hand(tmp_path):
    a = np.zeros((2, 3, 3), np.float32)
    b = np.ones((2, 3, 3), np.float32)
    d = raylab.compare(a, b)
    assert (d["width"], d["height"], d["pixels"], d["excluded"]) == (3, 2, 6, 0)
    assert d["mse"] == 1.0 and d["rmse"] == 1.0 and d["max_abs"] == 1.0
    # relative MSE divides by the reference squared plus 0.01.
    assert d["rel_mse"] == pytest.approx(1.0 / 1.01, rel=1e-12)
    assert d["psnr_db"] == pytest.approx(0.0, abs=1e-12)
    same = raylab.compare(b, b)
    assert same["mse"] == 0.0 and same["psnr_db"] is None
    with pytest.raises(ValueError, match=r"^the images differ in size: 3×2 against 2×2$"):
        raylab.compare(a, b[:, :2])
    with pytest.raises(ValueError, match=r"^a: expected an \(H, W, 3\) float array"):
        raylab.compare(np.zeros((2, 3), np.float32), b)


def test_compare_files_equals_cli(cli, repo, tmp_path):
    pa, pb = tmp_path / "a.pfm", tmp_path / "b.pfm"
    for p, spp in ((pa, 1), (pb, 16)):
        assert run_cli(cli, "render", repo / "scenes/cornell_path.toml", "-o", p, "--quiet", "--width=16", "--height=16", f"--spp={spp}").returncode == 0
    c = run_cli(cli, "compare", pa, pb, "--json")
    assert c.returncode == 0, c.stderr
    theirs = json.loads(c.stdout)
    mine = raylab.compare(pa, pb)
    for k in ("mse", "rmse", "rel_mse", "psnr_db", "max_abs", "pixels", "excluded", "width", "height"):
        assert mine[k] == theirs[k], k


def test_converge(repo):
    r = raylab.converge(repo / "scenes/cornell_path.toml", width=12, height=12, strategies=["uniform", "mis"], spp=[1, 4, 16], reference_spp=64)
    assert (r["width"], r["height"]) == (12, 12)
    assert [(p["strategy"], p["spp"]) for p in r["points"]] == [("uniform", 1), ("uniform", 4), ("uniform", 16), ("mis", 1), ("mis", 4), ("mis", 16)]
    assert set(r["slopes"]) == {"uniform", "mis"}
    # Error falls with more samples.
    for s in ("uniform", "mis"):
        mse = [p["mse"] for p in r["points"] if p["strategy"] == s]
        assert mse[-1] < mse[0]
        assert r["slopes"][s] < 0
    assert r["reference"].shape == (12, 12, 3)
    with pytest.raises(raylab.RaylabError, match=r"light-sampling strategies differ only under the direct and path integrators"):
        raylab.converge(repo / "scenes/cube.toml", width=8, height=8, spp=[1])
