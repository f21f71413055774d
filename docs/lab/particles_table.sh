#!/usr/bin/env bash
# Reproduces the second report's particle table: render time with and without a hierarchy
# for 8 spheres, 16 spheres, and 32 spheres of which 16 are in view. Median of REPEATS
# renders each, interleaved. Usage: docs/lab/particles_table.sh [REPEATS]  (from the
# repository root, after `cargo build --release`). Prints a markdown table.
set -euo pipefail
REPEATS=${1:-5}
R=target/release/raylab
ACCELS="none aabb sphere-bvh bvh"
SCENES="particles_8 particles_16 particles_16_of_32"
declare -A TIMES
for ((i = 0; i < REPEATS; i++)); do
  for scene in $SCENES; do
    for accel in $ACCELS; do
      t=$($R render "scenes/lab/$scene.toml" --accel "$accel" -q --json -o /tmp/particles_table.png |
        python3 -c 'import json,sys; s=json.load(sys.stdin); print(s["render_seconds"] + s["build_ms"] / 1e3, s["counters"]["prim_tests"] / s["counters"]["rays"])')
      TIMES[$scene,$accel]+="$t;"
    done
  done
done
echo "| accel | 8/8 ms | 16/16 ms | 16/32 ms | tests per ray (8/8, 16/16, 16/32) |"
echo "|---|---:|---:|---:|---|"
for accel in $ACCELS; do
  row="| $accel"
  tests=""
  for scene in $SCENES; do
    read -r ms per_ray < <(python3 -c 'import sys, statistics
runs = [r.split() for r in sys.argv[1].split(";") if r]
print(round(statistics.median(float(a) for a, _ in runs) * 1e3, 1), runs[0][1])' "${TIMES[$scene,$accel]}")
    row+=" | $ms"
    tests+="$(printf '%.1f' "$per_ray"), "
  done
  echo "$row | ${tests%, } |"
done
