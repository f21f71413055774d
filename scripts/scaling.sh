#!/usr/bin/env bash
# How raylab's builds, traversal and whole renders scale with threads, beside Embree 3 on the
# same rays (issue 11; docs/performance.md, "Scaling to 16 cores"). Three sweeps over THREADS:
#   trace:  `raylab bench MESH --accels bvh8 --peers embree` (primary, diffuse, shadow, packets);
#   build:  `raylab bench MESH --accels bvh,sbvh,lbvh,lbvh-ploc,bvh8 --peers embree --rays primary`
#           on a tiny ray grid, for the build times of every builder and of Embree's qualities;
#   render: `raylab render` of the bunny and dragon (Whitted) and the Cornell box (path traced),
#           wall and user seconds of the whole command;
#   kernels (not run unless asked): `raylab trace --accel bvh8` with the AVX2 and the AVX-512
#           kernel on the bench's ray sets, alternated twice, into $OUT/kernels.tsv.
# Writes each run's table (.md) and JSON to $OUT, and $OUT/render.tsv (scene, threads, wall s,
# user s, whether the image is byte for byte the first thread count's).
# The render sweep's scenes name their meshes, which the loader looks for in a `shared/scenes`
# folder beside the checkout or above it (on a machine without ../shared, copy them into
# `shared/scenes` in the checkout).
# Settings (environment): RAYLAB (the binary; default: build target/release/raylab with
# `--features peers,embree`, which needs Debian's libembree-dev, see scripts/peers.sh),
# RAYLAB_SHARED (the shared `scenes` folder, default ../shared/scenes), OUT (default
# target/scaling), THREADS (default "1 2 4 8 16"), MESHES (default "bunny dragon202k
# dragon871k"; tetra adds a 4.2M-triangle procedural mesh), RESOLUTION (camera-ray grid of
# the trace sweep, default 1024), TRACE_ACCELS (the structures of the trace sweep, default
# bvh8), REPEATS (default 3; trace's timed passes in the kernels
# sweep), SWEEPS (default "trace build render"; add kernels).
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${RAYLAB_SHARED:-../shared/scenes}
OUT=${OUT:-target/scaling}
THREADS=${THREADS:-"1 2 4 8 16"}
MESHES=${MESHES:-"bunny dragon202k dragon871k"}
RESOLUTION=${RESOLUTION:-1024}
TRACE_ACCELS=${TRACE_ACCELS:-bvh8}
REPEATS=${REPEATS:-3}
SWEEPS=${SWEEPS:-"trace build render"}
if [ -z "${RAYLAB:-}" ]; then
  cargo build --release -p raylab --features peers,embree
  RAYLAB=target/release/raylab
fi
mkdir -p "$OUT"

. scripts/meshes.sh

{ echo "cores: $(nproc)"; grep -m1 'model name' /proc/cpuinfo || true; command -v lscpu >/dev/null && lscpu | grep -E '^(Thread|Core|Socket|NUMA node\(s\)|L3)' || true; } | tee "$OUT/machine.txt"

for sweep in $SWEEPS; do
  for t in $THREADS; do
    case "$sweep" in
      trace|build)
        for m in $MESHES; do
          p=$(path_of "$m")
          [ -e "$p" ] || { echo "$p: not found (set RAYLAB_SHARED to the shared scenes folder)" >&2; exit 1; }
          echo "== $sweep, $m, $t thread(s)"
          if [ "$sweep" = trace ]; then
            "$RAYLAB" bench "$p" --accels "$TRACE_ACCELS" --peers embree --threads "$t" --repeats "$REPEATS" --resolution "$RESOLUTION" --json-out "$OUT/trace-$m-t$t.json" > "$OUT/trace-$m-t$t.md" 2>&1 || echo "FAILED: trace $m $t" | tee -a "$OUT/failed.txt"
          else
            "$RAYLAB" bench "$p" --accels bvh,sbvh,lbvh,lbvh-ploc,bvh8 --peers embree --rays primary --threads "$t" --repeats "$REPEATS" --resolution 32 --json-out "$OUT/build-$m-t$t.json" > "$OUT/build-$m-t$t.md" 2>&1 || echo "FAILED: build $m $t" | tee -a "$OUT/failed.txt"
          fi
        done ;;
      render)
        for s in "bunny 1280 960 8" "dragon 1280 960 8" "cornell_path 640 480 16"; do
          set -- $s
          echo "== render, $1, $t thread(s)"
          TIMEFORMAT="%R %U"
          times=$( { time "$RAYLAB" render "scenes/$1.toml" -o "$OUT/render-$1-t$t.png" --width "$2" --height "$3" --spp "$4" --threads "$t" > "$OUT/render-$1-t$t.txt" 2>&1; } 2>&1 ) || echo "FAILED: render $1 $t" | tee -a "$OUT/failed.txt"
          # The image must not depend on the thread count.
          same=-
          if [ "$t" != "${THREADS%% *}" ]; then
            if cmp -s "$OUT/render-$1-t$t.png" "$OUT/render-$1-t${THREADS%% *}.png"; then same=identical; else same=DIFFERS; fi
            rm -f "$OUT/render-$1-t$t.png"
          fi
          printf '%s\t%s\t%s\t%s\n' "$1" "$t" "$times" "$same" | tee -a "$OUT/render.tsv"
        done ;;
      kernels)
        for m in $MESHES; do
          p=$(path_of "$m")
          rays="$OUT/rays-$m"
          "$RAYLAB" bench "$p" --accels bvh8 --threads "$t" --repeats 1 --resolution "$RESOLUTION" --dump-rays "$rays/" > /dev/null 2>&1
          stem=$(basename "$p"); stem=${stem%%.*}
          for kind in primary diffuse shadow packets; do
            case "$kind" in
              shadow) args=(--rays "$rays/$stem-shadow.rays" --any-hit) ;;
              packets) args=(--rays "$rays/$stem-primary.rays" --packet 16) ;;
              *) args=(--rays "$rays/$stem-$kind.rays") ;;
            esac
            # Alternated twice: the machine's noise shows as the spread of each pair.
            for k in simd avx512 simd avx512; do
              echo "== kernels, $m, $kind, $k, $t thread(s)"
              line=$("$RAYLAB" trace "$p" "${args[@]}" --accel bvh8 --kernel "$k" --threads "$t" --repeats "$REPEATS" 2>&1 | tail -1)
              printf '%s\t%s\t%s\t%s\t%s\n' "$m" "$kind" "$k" "$t" "$(echo "$line" | grep -o '[0-9.]* Mrays/s' | cut -d' ' -f1)" | tee -a "$OUT/kernels.tsv"
            done
          done
          rm -rf "$rays"
        done ;;
      *) echo "unknown sweep '$sweep' in SWEEPS (expected trace, build, render, kernels)" >&2; exit 2 ;;
    esac
  done
done
echo "Tables and JSON in $OUT/."
[ ! -e "$OUT/failed.txt" ]
