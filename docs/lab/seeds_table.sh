#!/usr/bin/env bash
# Reproduces the first report's table (ray-mesh tests, ray-triangle tests, render time) for
# every acceleration structure: whole Whitted renders of the cube, bunny and teapot scenes.
# Usage: docs/lab/seeds_table.sh [WIDTH HEIGHT SPP]   (from the repository root, after
# `cargo build --release`). Prints a markdown table.
set -euo pipefail
W=${1:-320} H=${2:-240} SPP=${3:-4}
R=target/release/raylab
ACCELS=$( ($R render --accel help 2>&1 || true) | sed -n "s/.*(valid: \(.*\))/\1/p" | tr -d ",")
read -r -d '' ROW <<'PY' || true
import json, sys
s = json.load(sys.stdin)
c = s["counters"]
# Ray-mesh tests as the report counts them: a mesh is "tested" when its triangles are
# examined: by every ray without boxes, after a hit on its box with them.
mesh = {"none": c["rays"], "aabb": c["nodes_visited"]}.get(s["accel"])
mesh = "{:,}".format(mesh) if mesh is not None else "–"
print("| {} | {} | {:,} | {} | {:,} | {:.1f} | {:.1f} | {:.2f} |".format(
    sys.argv[1], s["accel"], c["rays"], mesh, c["prim_tests"], c["prim_tests"] / c["rays"], s["build_ms"], s["render_seconds"]))
PY
echo "| scene | accel | rays | ray–mesh tests | ray–primitive tests | tests per ray | build ms | render s |"
echo "|---|---|---:|---:|---:|---:|---:|---:|"
for scene in cube bunny teapot; do
  for accel in $ACCELS; do
    $R render "scenes/$scene.toml" --accel "$accel" --width "$W" --height "$H" --spp "$SPP" -q --json -o /tmp/seeds_table.png |
      python3 -c "$ROW" "$scene"
  done
done
