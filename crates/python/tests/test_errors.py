"""Errors become Python exceptions carrying raylab's file:line: field: message."""

import numpy as np
import pytest

import raylab
from conftest import run_cli

BAD_SCENE = """[camera]
from = [0, 0, 5]
at = [0, 0, 0]
vfov = "wide"
width = 32
height = 24
"""


def test_scene_error_carries_the_cli_message(cli, tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text(BAD_SCENE)
    with pytest.raises(raylab.RaylabError) as e:
        raylab.render(p)
    msg = str(e.value)
    assert msg.startswith(f"{p}:4: camera.vfov: ")
    assert (e.value.file, e.value.line, e.value.field) == (str(p), 4, "camera.vfov")
    # The very message the CLI prints.
    r = run_cli(cli, "render", p, "-o", tmp_path / "x.png", "--quiet")
    assert r.returncode != 0 and msg in r.stderr
    # RaylabError is a ValueError, so generic handlers catch it.
    assert isinstance(e.value, ValueError)
    with pytest.raises(raylab.RaylabError, match=f"^{p}:4: camera.vfov: "):
        raylab.Scene(p)
    with pytest.raises(raylab.RaylabError, match=f"^{p}:4: camera.vfov: "):
        raylab.trace(p, np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))


def test_missing_file(tmp_path):
    p = tmp_path / "nope.obj"
    with pytest.raises(raylab.RaylabError, match=f"^{p}: cannot read: "):
        raylab.build(p)
    assert raylab.RaylabError is raylab._native.RaylabError


def test_bad_overrides():
    with pytest.raises(ValueError, match=r"^spp: expected an integer from 1 to 1048576, found 0$"):
        raylab.render(None, spp=0)
    with pytest.raises(ValueError, match=r"^width: expected an integer from 1 to 16384, found True$"):
        raylab.render(None, width=True)
    with pytest.raises(ValueError, match=r"^integrator: unknown integrator `pathtracer` \(valid: whitted, direct, path, "):
        raylab.render(None, integrator="pathtracer")
    with pytest.raises(ValueError, match=r"^accel: unknown acceleration structure `octree` \(valid: none, bvh, "):
        raylab.Scene(None, accel="octree")
    with pytest.raises(TypeError, match=r"^render\(\) got an unexpected keyword argument 'sample_count' \(valid: width, height, spp, "):
        raylab.render(None, sample_count=4)
    with pytest.raises(TypeError, match=r"^sampler: expected a string, found int$"):
        raylab.render(None, sampler=3)
