#!/usr/bin/env bash
# Every test: the Rust workspace's, then the Python module's (built into target/pyvenv).
# This is the README's test command; CI (.ci/run) calls it.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace
bash crates/python/test.sh
