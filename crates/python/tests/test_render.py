"""raylab.render and Scene against `raylab render -o x.pfm`, byte for byte."""

import json

import numpy as np
import pytest

import raylab
from conftest import run_cli


def read_pfm(path):
    """(H, W, 3) float32, row 0 at the top, from raylab's PFM (little endian, rows bottom-up)."""
    data = path.read_bytes()
    parts = data.split(b"\n", 3)
    assert parts[0] == b"PF" and parts[2] == b"-1.0"
    w, h = map(int, parts[1].split())
    body = parts[3]
    assert len(body) == w * h * 12
    return body, np.flipud(np.frombuffer(body, "<f4").reshape(h, w, 3))


CASES = [
    ("scenes/cube.toml", dict(width=48, height=36, spp=4)),
    ("scenes/cornell_path.toml", dict(width=40, height=40, spp=4, max_depth=4, threads=2)),
    ("scenes/bunny.toml", dict(width=32, height=24, spp=1, accel="kdtree", integrator="normals")),
    (None, dict(width=40, height=30, spp=1, sampler="sobol", seed=7)),
]


@pytest.mark.parametrize("scene,overrides", CASES)
def test_render_equals_cli_pfm_byte_for_byte(cli, repo, tmp_path, scene, overrides):
    out = tmp_path / "x.pfm"
    flags = [f"--{k.replace('_', '-')}={v}" for k, v in overrides.items()]
    args = ["render", *([repo / scene] if scene else []), "-o", out, "--quiet", *flags]
    r = run_cli(cli, *args)
    assert r.returncode == 0, r.stderr
    body, expected = read_pfm(out)
    img = raylab.render(repo / scene if scene else None, **overrides)
    assert img.shape == (overrides["height"], overrides["width"], 3) and img.dtype == np.float32
    assert img.flags["C_CONTIGUOUS"]
    assert np.flipud(img).astype("<f4").tobytes() == body
    np.testing.assert_array_equal(img, expected)
    assert img.max() > 0


def test_scene_render_equals_module_render_and_settings_change(repo):
    s = raylab.Scene(repo / "scenes/cube.toml", width=24, height=18, spp=1)
    assert s.settings["width"] == 24 and s.settings["spp"] == 1 and s.settings["integrator"] == "whitted"
    np.testing.assert_array_equal(s.render(), raylab.render(repo / "scenes/cube.toml", width=24, height=18, spp=1))
    # Pure settings apply in place; the size reloads; accel rebuilds: each equals a fresh load.
    s.set(spp=4, seed=3)
    np.testing.assert_array_equal(s.render(), raylab.render(repo / "scenes/cube.toml", width=24, height=18, spp=4, seed=3))
    s.set(width=30, accel="grid")
    assert s.settings["accel"] == "grid" and s.accel_stats["name"] == "grid"
    np.testing.assert_array_equal(s.render(), raylab.render(repo / "scenes/cube.toml", width=30, height=18, spp=4, seed=3, accel="grid"))
    # As in the CLI, a non-square count is rounded up to the next square for the jittered sampler.
    s.set(spp=5, sampler="jittered")
    assert s.settings["spp"] == 9


def test_aovs(repo):
    s = raylab.Scene(repo / "scenes/cube.toml", width=16, height=12, spp=4)
    out = s.render(aovs=["normal", "depth", "albedo", "variance"])
    assert set(out) == {"image", "normal", "depth", "albedo", "variance"}
    for name in ("image", "normal", "depth", "albedo"):
        assert out[name].shape == (12, 16, 3) and out[name].dtype == np.float32
    np.testing.assert_array_equal(out["depth"], raylab.render(repo / "scenes/cube.toml", width=16, height=12, spp=4, integrator="depth"))
    # `normals` (the integrator's name) stays an alias of the CLI's `normal`.
    np.testing.assert_array_equal(s.render(aovs=["normals"])["normals"], out["normal"])
    # The scene's own integrator is back after the AOVs.
    assert s.settings["integrator"] == "whitted"
    np.testing.assert_array_equal(out["image"], s.render())
    with pytest.raises(ValueError, match=r"^aovs: unknown AOV `path` \(valid: albedo, normal, depth, variance, heatmap, heatmap-tests\)$"):
        s.render(aovs=["path"])


def test_variance_aov(repo):
    """The beauty render's per-pixel variance of luminance: 0 where every sample sees the
    same flat background, positive where samples straddle a silhouette."""
    s = raylab.Scene(repo / "scenes/spheres_phong.toml", width=16, height=12, spp=4, seed=7)
    out = s.render(aovs=["variance"])
    var = out["variance"]
    assert var.shape == (12, 16) and var.dtype == np.float32
    lum = out["image"] @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
    flat = np.isclose(lum, lum[0, 0]) & (var == 0)
    assert flat[0, 0], "the top-left pixel sees only the background"
    # Samples are >= 0, so each is at most 4x its pixel's mean L; the unbiased sample variance
    # of n values in [0, 4L] is at most n/(n-1) (4L)^2/4, and divided by n: (4L)^2/12.
    bound = 16 * lum**2 / 12
    assert var.max() > 0 and (var <= bound * (1 + 1e-5)).all()


def test_scene_inspection_equals_cli_inspect(cli, repo):
    for name in ("scenes/cube.toml", "scenes/teapot_patches.toml", "scenes/spheres_phong.toml"):
        r = run_cli(cli, "inspect", repo / name, "--json")
        assert r.returncode == 0, r.stderr
        expected = json.loads(r.stdout)
        s = raylab.Scene(repo / name)
        assert s.counts == expected["counts"], name
        # JSON prints the f32 bounds in their shortest form; compare as f32.
        np.testing.assert_array_equal(np.array(s.bounds, np.float32), np.array(expected["bounds"], np.float32))
        assert s.memory == {"geometry": expected["geometry_bytes"], "textures": expected["texture_bytes"], "accel": expected["accel"]["memory_bytes"]}
        stats = s.accel_stats
        for k in ("name", "primitives", "interior_nodes", "leaves", "max_depth", "references", "leaf_histogram", "sah_cost", "memory_bytes"):
            assert stats[k] == expected["accel"][k], (name, k)
        for k in ("width", "height", "spp", "sampler", "max_depth", "integrator", "accel", "seed"):
            assert s.settings[k] == expected["render"][k], (name, k)


def test_scene_trace_by_hand(repo):
    s = raylab.Scene(repo / "scenes/cube.toml")
    c = s.counts
    # meshes/cube.obj (12 triangles) and the ground quad (2).
    assert (c["meshes"], c["triangles"], c["primitives"], c["spheres"]) == (2, 14, 14, 0)
    v, f = s.triangles()
    assert f.shape == (14, 3) and v.dtype == np.float32
    # Straight down onto the ground plane y = 0 outside the cube: t = 5.
    h = s.trace(np.array([[4, 5, 4]], np.float32), np.array([[0, -1, 0]], np.float32))
    assert h["t"][0] == 5.0 and h["prim"][0] >= 12
