#!/usr/bin/env bash
# Reproduces the second report's hair comparison (§4.2, figure 11): the hair scene as
# tessellated tubes of 16, 8 and 4 sides and by direct ray–curve intersection. Render time
# (best of 3, one thread), primitives, and the image difference of each against direct.
# Usage: docs/lab/hair_table.sh [SPP]   (from the repository root, after
# `cargo build --release`). Prints a markdown table; images go to /tmp/hair_table/.
set -euo pipefail
SPP=${1:-16}
R=target/release/raylab
OUT=/tmp/hair_table
mkdir -p "$OUT"
for mode in direct tube16 tube8 tube4; do
  best=""
  for _ in 1 2 3; do
    json=$($R render "scenes/lab/hair_$mode.toml" --spp "$SPP" --threads 1 -q --json -o "$OUT/$mode.exr")
    t=$(python3 -c 'import json,sys; print(json.load(sys.stdin)["render_seconds"])' <<<"$json")
    if [ -z "$best" ] || python3 -c "import sys; sys.exit(not $t < $best)"; then best=$t; keep=$json; fi
  done
  echo "$keep" >"$OUT/$mode.json"
  $R render "scenes/lab/hair_$mode.toml" --spp "$SPP" --integrator albedo -q -o "$OUT/$mode-albedo.exr"
done
echo "| mode | primitives | build ms | render s (1 thread) | tests per ray | MSE vs direct | PSNR dB | coverage MSE (albedo) |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|"
for mode in direct tube16 tube8 tube4; do
  if [ "$mode" = direct ]; then diff="– | – | –"; else
    shaded=$($R compare "$OUT/$mode.exr" "$OUT/direct.exr" --json)
    albedo=$($R compare "$OUT/$mode-albedo.exr" "$OUT/direct-albedo.exr" --json)
    diff=$(python3 -c 'import json,sys; a=json.loads(sys.argv[1]); b=json.loads(sys.argv[2]); print("{:.2e} | {:.1f} | {:.2e}".format(a["mse"], a["psnr_db"], b["mse"]))' "$shaded" "$albedo")
  fi
  python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); c=s["counters"]; print("| {} | {:,} | {:.1f} | {:.2f} | {:.2f} | {} |".format(sys.argv[2], s["primitives"], s["build_ms"], s["render_seconds"], c["prim_tests"]/c["rays"], sys.argv[3]))' "$OUT/$mode.json" "$mode" "$diff"
done
