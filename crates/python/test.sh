#!/usr/bin/env bash
# Builds the `raylab` Python module into a virtualenv under target/ and runs its pytest
# suite against the release CLI (`.ci/run` calls this after `cargo test --workspace`).
# Needs Python 3.9+ with venv and pip, and network access to PyPI the first time.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
venv=$root/target/pyvenv
python=${PYTHON:-python3}
if [ ! -x "$venv/bin/python" ]; then
    "$python" -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check "maturin>=1.9.4,<2" numpy pytest
# The CLI the tests compare the module's results with, and the wheel, both in release.
cargo build --release -p raylab
rm -f "$root"/target/wheels/raylab-*.whl
CARGO_TARGET_DIR=$root/target "$venv/bin/maturin" build --release -m crates/python/Cargo.toml -i "$venv/bin/python" -o "$root/target/wheels"
"$venv/bin/python" -m pip install -q --disable-pip-version-check --force-reinstall --no-deps "$root"/target/wheels/raylab-*.whl
RAYLAB_BIN=$root/target/release/raylab "$venv/bin/python" -m pytest crates/python/tests -q -p no:cacheprovider
