#!/bin/bash
# Renders a small bench report and takes screenshots of it in headless Chromium, to see the
# report as a reader does (issue 13): the charts, the log axes, the shared heat-map scale.
#
#   scripts/report-screenshot.sh [OUTDIR] [raylab binary]
#
# Writes OUTDIR/report.html and OUTDIR/report-1.png, -2.png, ... (1400×3000 each, one per
# 2,900 pixels of page). Installs Debian's chromium when it is missing (needs root). Runs the
# cube and the bunny (two scenes, so the scaling plots appear) at 32 rays wide, one repeat.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
out=$(realpath -m "${1:-$repo/target/report-screenshot}")
raylab=${2:-$repo/target/debug/raylab}
mkdir -p "$out"
if ! command -v chromium >/dev/null; then
    apt-get update -qq && apt-get install -y -qq chromium
fi
[ -x "$raylab" ] || (cd "$repo" && cargo build -p raylab)
"$raylab" bench "$repo/scenes/cube.toml" "$repo/scenes/bunny.toml" --resolution 32 --repeats 1 --heatmap-width 64 --report "$out/report.html" >/dev/null
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
# A page taller than one screenshot is shot in pieces: each copy of the page is shifted up.
pages=${PAGES:-4}
for ((i = 0; i < pages; i++)); do
    shifted="$out/report-shift-$i.html"
    sed "s|<body>|<body style='margin-top:-$((i * 2900))px'>|" "$out/report.html" > "$shifted"
    chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
        --disable-component-update --disable-sync --user-data-dir="$profile" \
        --screenshot="$out/report-$((i + 1)).png" --window-size=1400,3000 "file://$shifted" 2>/dev/null
    rm "$shifted"
done
echo "report: $out/report.html; screenshots: $out/report-1.png … report-$pages.png"
