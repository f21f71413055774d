#!/usr/bin/env bash
# The Utah teapot's 32 bicubic patches, tessellated at 4, 10, 20 and 40 subdivisions per
# patch side against direct ray–patch intersection (Newton): primitives, build and render
# time (best of 3), tests per ray, and the image difference of each against direct.
# Usage: docs/lab/patch_table.sh [SPP]   (from the repository root, after
# `cargo build --release`). Prints a markdown table; images go to /tmp/patch_table/.
set -euo pipefail
SPP=${1:-4}
R=target/release/raylab
OUT=/tmp/patch_table
mkdir -p "$OUT"
# Tessellated variants beside the example scene, so that its file names resolve.
for n in 4 10 20 40; do
  sed "s/^subdivisions = 10$/subdivisions = $n/" scenes/teapot_patches.toml >"scenes/.patch_table_$n.toml"
done
trap 'rm -f scenes/.patch_table_*.toml' EXIT
for v in direct 4 10 20 40; do
  scene="scenes/.patch_table_$v.toml"
  [ "$v" = direct ] && scene=scenes/lab/teapot_patches_direct.toml
  best=""
  for _ in 1 2 3; do
    json=$($R render "$scene" --spp "$SPP" --width 320 --height 240 -q --json -o "$OUT/$v.exr")
    t=$(python3 -c 'import json,sys; print(json.load(sys.stdin)["render_seconds"])' <<<"$json")
    if [ -z "$best" ] || python3 -c "import sys; sys.exit(not $t < $best)"; then best=$t; keep=$json; fi
  done
  echo "$keep" >"$OUT/$v.json"
done
echo "| teapot | primitives | build ms | render s | tests per ray | MSE vs direct | PSNR dB |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for v in direct 4 10 20 40; do
  if [ "$v" = direct ]; then diff="– | –"; name="direct (Newton)"; else
    diff=$($R compare "$OUT/$v.exr" "$OUT/direct.exr" --json | python3 -c 'import json,sys; a=json.load(sys.stdin); print("{:.2e} | {:.1f}".format(a["mse"], a["psnr_db"]))')
    name="$v subdivisions"
  fi
  python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); c=s["counters"]; print("| {} | {:,} | {:.1f} | {:.2f} | {:.2f} | {} |".format(sys.argv[2], s["primitives"], s["build_ms"], s["render_seconds"], c["prim_tests"]/c["rays"], sys.argv[3]))' "$OUT/$v.json" "$name" "$diff"
done
