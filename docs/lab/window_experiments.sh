#!/usr/bin/env bash
# Redoes the third report's window experiments on scenes/window_floor.toml (a Richter-style
# window standing on a glossy floor). Usage, from the repository root after
# `cargo build --release`: docs/lab/window_experiments.sh [OUT]   (default /tmp/window_exp)
#   1. the floor's specular lobe: Phong exponent 100, 500, 2000 and three Cook-Torrance
#      (f0, m) of the report, rendered with MIS -> OUT/materials/*.png;
#   2. convergence of uniform, cells (6×6), solid-angle and mis without shadows, and
#   3. with two spheres casting shadows on the reflection (the report's second scene);
#   4. the number of cells k×k at 16 spp against the reference of 2.
# MSE is averaged over SEEDS (default 4) independent runs: single images are too noisy
# (glossy highlights) to rank strategies. Prints the tables of docs/light-transport.md;
# CSV, plots and images stay under OUT.
set -euo pipefail
OUT=${1:-/tmp/window_exp}
R=target/release/raylab
SIZE="--width 100 --height 100"
SPP=1,2,4,8,16,32,64
SEEDS=${SEEDS:-4}
mkdir -p "$OUT/materials"
TEX="$(pwd)/scenes/textures/richter_window.ppm"
# A copy of the scene with the texture path made absolute, the floor material replaced by
# $2 (TOML lines) and $3 appended.
variant() {
  python3 - "$1" "$2" "${3:-}" "$TEX" <<'PY'
import sys, re
out, floor, extra, tex = sys.argv[1:]
s = open("scenes/window_floor.toml").read().replace('"textures/richter_window.ppm"', '"%s"' % tex)
s = re.sub(r'(\[\[materials\]\]\nname = "floor"\n)(?:[^\[]*)', lambda m: m.group(1) + floor + "\n\n", s)
open(out, "w").write(s + extra)
PY
}

echo "## 1. Floor materials (200×200, 64 spp, mis)"
echo "| floor | render s |"
echo "|---|---:|"
for spec in "phong_e100|type = \"phong\"
kd = 0.8
ks = 0.2
exponent = 100" "phong_e500|type = \"phong\"
kd = 0.8
ks = 0.2
exponent = 500" "phong_e2000|type = \"phong\"
kd = 0.8
ks = 0.2
exponent = 2000" "ct_f0.0366_m0.276|type = \"cooktorrance\"
diffuse = 0.8
specular = 0.2
distribution = \"beckmann\"
geometry = \"v-cavity\"
f0 = 0.0366
roughness = 0.276" "ct_f0.025_m0.076|type = \"cooktorrance\"
diffuse = 0.8
specular = 0.2
distribution = \"beckmann\"
geometry = \"v-cavity\"
f0 = 0.025
roughness = 0.076" "ct_f0.03_m0.01|type = \"cooktorrance\"
diffuse = 0.8
specular = 0.2
distribution = \"beckmann\"
geometry = \"v-cavity\"
f0 = 0.03
roughness = 0.01"; do
  name=${spec%%|*}
  variant "$OUT/$name.toml" "${spec#*|}"
  t=$($R render "$OUT/$name.toml" --width 200 --height 200 --spp 64 --light-sampling mis -q --json -o "$OUT/materials/$name.png" | python3 -c 'import json,sys; print(round(json.load(sys.stdin)["render_seconds"], 2))')
  echo "| $name | $t |"
done

BLOCKERS='
[[shapes]]
type = "sphere"
center = [-0.6, 0.45, -0.4]
radius = 0.45

[[shapes]]
type = "sphere"
center = [0.7, 0.35, 0.3]
radius = 0.35
'
variant "$OUT/plain.toml" 'type = "phong"
kd = 0.8
ks = 0.2
exponent = 500'
variant "$OUT/shadows.toml" 'type = "phong"
kd = 0.8
ks = 0.2
exponent = 500' "$BLOCKERS"

table() { # CSVs of raylab converge (one per seed) -> mean MSE at 1, 16, 64 spp, seconds at 64, slope
  python3 - "$@" <<'PY'
import csv, math, sys
from collections import defaultdict
mse, secs = defaultdict(list), defaultdict(list)
for f in sys.argv[1:]:
    for r in csv.DictReader(open(f)):
        mse[r["strategy"], int(r["spp"])].append(float(r["mse"]))
        secs[r["strategy"], int(r["spp"])].append(float(r["seconds"]))
mean = lambda xs: sum(xs) / len(xs)
print("| strategy | MSE 1 spp | MSE 16 spp | MSE 64 spp | s at 64 spp | slope |")
print("|---|---:|---:|---:|---:|---:|")
for s in dict.fromkeys(k[0] for k in mse):
    spps = sorted(n for (t, n) in mse if t == s)
    xs = [math.log(n) for n in spps]; ys = [math.log(mean(mse[s, n])) for n in spps]
    mx, my = mean(xs), mean(ys)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    print(f"| {s} | {mean(mse[s, 1]):.3g} | {mean(mse[s, 16]):.3g} | {mean(mse[s, 64]):.3g} | {mean(secs[s, 64]):.2f} | {slope:.2f} |")
PY
}

for scene in plain shadows; do
  echo "## $scene: convergence (100×100, reference mis at 4096 spp, MSE averaged over $SEEDS seeds)"
  $R converge "$OUT/$scene.toml" $SIZE --light-cells 6 --strategies uniform,cells,solid-angle,mis --spp $SPP --reference-spp 4096 --seed 100 -o "$OUT/conv_$scene/0" >/dev/null
  for ((seed = 1; seed < SEEDS; seed++)); do
    $R converge "$OUT/$scene.toml" $SIZE --light-cells 6 --strategies uniform,cells,solid-angle,mis --spp $SPP --seed $seed --reference "$OUT/conv_$scene/0/reference.exr" -o "$OUT/conv_$scene/$seed" >/dev/null
  done
  table "$OUT"/conv_$scene/*/convergence.csv
done

echo "## Number of cells (plain scene, 16 spp, cells strategy, mean over $SEEDS seeds)"
for k in 1 2 4 6 8 11 16; do
  for ((seed = 0; seed < SEEDS; seed++)); do
    $R converge "$OUT/plain.toml" $SIZE --light-cells $k --strategies cells --spp 16 --seed $seed --reference "$OUT/conv_plain/0/reference.exr" -o "$OUT/cells_$k/$seed" >/dev/null
  done
done
python3 - "$OUT" <<'PY'
import csv, glob, sys
print("| cells | MSE | s |")
print("|---|---:|---:|")
for k in (1, 2, 4, 6, 8, 11, 16):
    rows = [list(csv.DictReader(open(f)))[0] for f in glob.glob(f"{sys.argv[1]}/cells_{k}/*/convergence.csv")]
    print(f"| {k}×{k} | {sum(float(r['mse']) for r in rows) / len(rows):.3g} | {sum(float(r['seconds']) for r in rows) / len(rows):.2f} |")
PY
