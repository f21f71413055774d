"""Shared fixtures: the repository root, the shared scenes, and the `raylab` CLI binary that
the Python results are checked against (built by `.ci/run` with `cargo build --release`)."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]
SHARED = REPO.parent / "shared" / "scenes"


@pytest.fixture(scope="session")
def repo() -> pathlib.Path:
    return REPO


@pytest.fixture(scope="session")
def bunny() -> pathlib.Path:
    p = SHARED / "bunny_69451.obj"
    if not p.exists():
        pytest.fail(f"{p} is missing: the shared meshes live in ../shared/scenes beside the repository")
    return p


@pytest.fixture(scope="session")
def cli() -> str:
    """Path of the `raylab` binary: $RAYLAB_BIN, or target/release/raylab."""
    exe = os.environ.get("RAYLAB_BIN") or str(REPO / "target" / "release" / "raylab")
    if not os.path.exists(exe):
        pytest.fail(f"{exe} not found: run `cargo build --release -p raylab` first (or set RAYLAB_BIN)")
    return exe


def run_cli(cli: str, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([cli, *map(str, args)], cwd=REPO, capture_output=True, text=True, timeout=300)
