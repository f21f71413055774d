"""raylab.trace and raylab.build against the CLI's `trace`, the oracle and hand-computed hits."""

import json

import numpy as np
import pytest

import raylab
from conftest import run_cli

CHUNK = 1024  # rays per parallel task in raylab_lab::trace, whose sums run in chunk order


def cli_checksums(hits: dict, any_hit: bool):
    """Hit count and t sum in the order `raylab trace` adds them: f64 sums per chunk of
    1024 rays (cumsum adds one value at a time, unlike np.sum's pairwise sum), then the
    chunk sums in chunk order."""
    if any_hit:
        return int(hits["hit"].sum()), 0.0
    t = hits["t"].astype(np.float64)
    hit = hits["prim"] >= 0
    chunk_sums = [np.cumsum(np.where(hit[i:i + CHUNK], t[i:i + CHUNK], 0.0))[-1] for i in range(0, len(t), CHUNK)]
    total = np.cumsum(np.array(chunk_sums))[-1] if chunk_sums else 0.0
    return int(hit.sum()), float(total)


@pytest.fixture(scope="module")
def ray_files(cli, tmp_path_factory, repo):
    out = tmp_path_factory.mktemp("rays")
    r = run_cli(cli, "bench", repo / "scenes" / "bunny.toml", "--accels", "bvh", "--repeats", "1", "--resolution", "96", "--dump-rays", out)
    assert r.returncode == 0, r.stderr
    files = {p.stem.split("-")[-1]: p for p in out.glob("*.rays")}
    assert set(files) == {"primary", "diffuse", "shadow"}
    return files


@pytest.mark.parametrize("kind", ["primary", "diffuse", "shadow"])
@pytest.mark.parametrize("accel", ["bvh", "kdtree", "grid", "sbvh"])
def test_hits_equal_cli_trace_bit_for_bit(cli, repo, ray_files, kind, accel):
    any_hit = kind == "shadow"
    path = ray_files[kind]
    r = run_cli(cli, "trace", repo / "scenes" / "bunny.toml", "--rays", path, "--accel", accel, "--repeats", "1", "--json", *(["--any-hit"] if any_hit else []))
    assert r.returncode == 0, r.stderr
    expected = json.loads(r.stdout)
    rays = raylab.read_rays(path)
    hits = raylab.trace(repo / "scenes" / "bunny.toml", rays["origins"], rays["directions"], tmin=rays["tmin"], tmax=rays["tmax"], accel=accel, any_hit=any_hit)
    n, t_sum = cli_checksums(hits, any_hit)
    assert n == expected["hits"]
    # Bit for bit: the same f32 distances summed in the same order give the same f64.
    assert t_sum == expected["t_sum"]
    assert expected["rays"] == len(rays["origins"])


def test_every_structure_matches_the_oracle_ray_by_ray(repo):
    bunny = repo.parent / "shared/scenes/bunny_4968.obj"
    rng = np.random.default_rng(7)
    n = 2000
    origins = rng.uniform(-0.3, 0.3, (n, 3)).astype(np.float32)
    directions = rng.normal(size=(n, 3)).astype(np.float32)
    oracle = raylab.build(bunny, accel="none")
    ref = oracle.trace(origins, directions)
    ref_any = oracle.trace(origins, directions, any_hit=True)
    assert 0 < (ref["prim"] >= 0).sum() < n
    for name in raylab.accels():
        s = raylab.build(bunny, accel=name)
        s.validate()
        got = s.trace(origins, directions)
        np.testing.assert_array_equal(got["t"], ref["t"], err_msg=name)
        hit = ref["prim"] >= 0
        # Ties between two triangles at the same t may pick either; the distances agree.
        assert (got["prim"] >= 0).tolist() == hit.tolist(), name
        np.testing.assert_array_equal(s.trace(origins, directions, any_hit=True)["hit"], ref_any["hit"], err_msg=name)
        assert (got["prim_tests"][hit] >= 1).all()


def test_single_triangle_by_hand():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    tri = raylab.build(vertices, np.array([[0, 1, 2]]), accel="bvh")
    o = np.array([[0.2, 0.3, 2.0], [0.2, 0.3, 2.0], [2.0, 2.0, 2.0], [0.2, 0.3, 2.0]], np.float32)
    d = np.array([[0, 0, -1], [0, 0, -2], [0, 0, -1], [0, 0, 1]], np.float32)
    h = tri.trace(o, d)
    # Unit direction: t = 2; direction of length 2: t = 1 (t is in units of the direction).
    np.testing.assert_array_equal(h["t"], np.array([2.0, 1.0, np.inf, np.inf], np.float32))
    np.testing.assert_array_equal(h["prim"], [0, 0, -1, -1])
    # Barycentrics: p = (1 - u - v) p0 + u p1 + v p2, so (u, v) = (x, y) on this triangle.
    np.testing.assert_allclose(h["u"][:2], [0.2, 0.2], rtol=1e-6)
    np.testing.assert_allclose(h["v"][:2], [0.3, 0.3], rtol=1e-6)
    assert h["t"].dtype == np.float32 and h["prim"].dtype == np.int64
    # t interval (tmin, tmax]: the hit at t = 2 is inside (0, 2] but not (0, 1.5] nor (2, 9].
    assert tri.trace(o[:1], d[:1], tmax=2.0)["prim"][0] == 0
    assert tri.trace(o[:1], d[:1], tmax=1.5)["prim"][0] == -1
    assert tri.trace(o[:1], d[:1], tmin=2.0, tmax=9.0)["prim"][0] == -1
    per_ray = tri.trace(o, d, tmax=np.array([1.5, 5, 5, 5], np.float32))
    np.testing.assert_array_equal(per_ray["prim"], [-1, 0, -1, -1])
    np.testing.assert_array_equal(tri.trace(o, d, any_hit=True)["hit"], [True, True, False, False])
    st = tri.stats
    assert st["primitives"] == 1 and st["leaves"] == 1 and st["name"] == "bvh"
    assert tri.primitives == 1 and tri.bounds == ((0.0, 0.0, 0.0), (1.0, 1.0, 0.0))


def test_layouts_and_dtypes_give_the_same_answers(bunny):
    rng = np.random.default_rng(3)
    o = rng.uniform(-0.2, 0.2, (500, 3)).astype(np.float32)
    d = rng.normal(size=(500, 3)).astype(np.float32)
    s = raylab.build(bunny)
    ref = s.trace(o, d)
    for oo, dd in [(o.astype(np.float64), d.astype(np.float64)), (np.asfortranarray(o), np.asfortranarray(d)), (np.hstack([o, o])[:, :3], d), (o.tolist(), d.tolist())]:
        got = s.trace(oo, dd)
        for k in ref:
            np.testing.assert_array_equal(got[k], ref[k], err_msg=k)


def test_wrong_dtype_and_shape_raise_value_error(bunny):
    s = raylab.build(bunny)
    o = np.zeros((4, 3), np.float32)
    d = np.ones((4, 3), np.float32)
    with pytest.raises(ValueError, match=r"^origins: expected a float array of shape \(N, 3\), got an array of dtype int32 and shape \(4, 3\)$"):
        s.trace(o.astype(np.int32), d)
    with pytest.raises(ValueError, match=r"^directions: expected a float array of shape \(N, 3\), got an array of dtype float32 and shape \(4, 4\)$"):
        s.trace(o, np.ones((4, 4), np.float32))
    with pytest.raises(ValueError, match=r"^directions: expected shape \(4, 3\) like origins, got \(5, 3\)$"):
        s.trace(o, np.ones((5, 3), np.float32))
    with pytest.raises(ValueError, match=r"^tmax: expected a float or a float array of shape \(4,\), got an array of dtype float32 and shape \(3,\)$"):
        s.trace(o, d, tmax=np.ones(3, np.float32))
    bad = d.copy()
    bad[2] = 0
    with pytest.raises(ValueError, match=r"^ray 2 is not valid: its direction is zero$"):
        s.trace(o, bad)
    nan = o.copy()
    nan[1, 0] = np.nan
    with pytest.raises(ValueError, match=r"^ray 1 is not valid: its origin is not finite$"):
        raylab.trace(bunny, nan, d)
    with pytest.raises(ValueError, match=r"^accel: unknown acceleration structure `octree` \(valid: none, bvh, "):
        raylab.trace(bunny, o, d, accel="octree")
    with pytest.raises(ValueError, match=r"^indices: triangle 0 refers to vertex 3, but there are 3 vertices$"):
        raylab.build(np.zeros((3, 3), np.float32), np.array([[0, 1, 3]]))
    with pytest.raises(ValueError, match=r"^indices: expected an integer array of shape \(F, 3\)"):
        raylab.build(np.zeros((3, 3), np.float32), np.array([[0.0, 1.0, 2.0]]))


def test_read_only_arrays_are_accepted(bunny):
    # The rays are only borrowed for reading (a read-only float32 C array is used in place).
    o = np.zeros((1000, 3), np.float32)
    o.setflags(write=False)
    d = np.tile(np.array([[0, 0, 1]], np.float32), (1000, 1))
    h = raylab.trace(bunny, o, d)
    assert h["t"].shape == (1000,)


def test_ray_files_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    o = rng.normal(size=(10, 3)).astype(np.float32)
    d = rng.normal(size=(10, 3)).astype(np.float32)
    p = tmp_path / "x.rays"
    raylab.write_rays(p, o, d, tmin=0.5, tmax=np.arange(10, dtype=np.float32) + 1)
    assert p.stat().st_size == 8 + 10 * 32
    r = raylab.read_rays(p)
    np.testing.assert_array_equal(r["origins"], o)
    np.testing.assert_array_equal(r["directions"], d)
    np.testing.assert_array_equal(r["tmin"], np.full(10, 0.5, np.float32))
    np.testing.assert_array_equal(r["tmax"], np.arange(10, dtype=np.float32) + 1)
    p.write_bytes(b"\x01\0\0\0\0\0\0\0\0\0")
    with pytest.raises(raylab.RaylabError, match=r"the header says 1 rays \(32 bytes\) but 2 bytes follow$"):
        raylab.read_rays(p)
