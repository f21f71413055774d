#!/usr/bin/env bash
# Regenerates the table "Measured: strategies on scenes/area_lights.toml" of
# docs/light-transport.md: runs the `raylab converge` command quoted there and prints the
# markdown table (MSE at 1, 16 and 256 spp, seconds at 256 spp, and the least-squares slope
# of ln MSE against ln spp over all budgets, as `raylab converge` fits it).
# Usage: docs/lab/strategies_table.sh [OUT]   (from the repository root, after
# `cargo build --release`; about two minutes on 2 busy cores). The study goes to OUT (/tmp/strategies).
set -euo pipefail
OUT=${1:-/tmp/strategies}
R=${RAYLAB:-target/release/raylab}
$R converge scenes/area_lights.toml --width 128 --height 80 \
  --strategies uniform,solid-angle,cells,bsdf,mis --spp 1,2,4,8,16,32,64,128,256 \
  --reference-spp 4096 -o "$OUT" >/dev/null
python3 - "$OUT/convergence.csv" <<'PY'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
def num(x):
    # Three significant figures, in the table's style: 0.94, 1.54, 2.12e-1.
    return f"{x:.2f}" if x >= 1 else f"{x:.2e}".replace("e-0", "e-")
print("| strategy | MSE, 1 spp | MSE, 16 spp | MSE, 256 spp | seconds at 256 spp | slope |")
print("|---|---:|---:|---:|---:|---:|")
for s in dict.fromkeys(r["strategy"] for r in rows):
    pts = {int(r["spp"]): r for r in rows if r["strategy"] == s}
    xs = [math.log(n) for n in pts]; ys = [math.log(float(pts[n]["mse"])) for n in pts]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    mse = lambda n: num(float(pts[n]["mse"]))
    print(f"| {s} | {mse(1)} | {mse(16)} | {mse(256)} | {float(pts[256]['seconds']):.2f} | {slope:.2f} |".replace("| -", "| −"))
PY
