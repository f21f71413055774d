#!/usr/bin/env bash
# raylab's best structure against Embree 3, obvhs and the `bvh` crate on the same rays
# (issue 11; docs/performance.md, "Peers, side by side"). From a clean clone:
#   1. installs Debian's libembree-dev when its header is missing (as root, or with sudo);
#   2. builds raylab with the peers (`--features peers,embree`, the release profile);
#   3. runs `raylab bench --peers embree,obvhs,bvh` (Embree HIGH, MEDIUM and HIGH with
#      RTC_SCENE_FLAG_ROBUST) on bunny 69k, dragon 202k and 871k and
#      a procedural Sierpinski tetrahedron of 4.2M triangles (`raylab gen tetra --size 10`),
#      for 1 and 2 threads, writing each run's tables (.md) and JSON to $OUT.
# Settings (environment): RAYLAB_SHARED (the shared `scenes` folder, default
# ../shared/scenes beside the repository), OUT (default target/peers), REPEATS (timed
# passes after the warm-up, default 3), RESOLUTION (width of the camera-ray grid, default
# 512: 196k primary rays), THREADS (default "1 2"), MESHES (default all four:
# bunny dragon202k dragon871k tetra). Example: MESHES=bunny REPEATS=1 scripts/peers.sh
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${RAYLAB_SHARED:-../shared/scenes}
OUT=${OUT:-target/peers}
REPEATS=${REPEATS:-3}
RESOLUTION=${RESOLUTION:-512}
THREADS=${THREADS:-"1 2"}
MESHES=${MESHES:-"bunny dragon202k dragon871k tetra"}

if [ ! -e /usr/include/embree3/rtcore.h ]; then
  echo "Installing libembree-dev (Embree 3)..."
  SUDO=
  if [ "$(id -u)" != 0 ]; then SUDO=sudo; fi
  $SUDO apt-get update
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y libembree-dev
fi

cargo build --release -p raylab --features peers,embree
RAYLAB=target/release/raylab
mkdir -p "$OUT"

. scripts/meshes.sh

# A run whose answers differ from the oracle beyond the tolerance fails; the others still run.
failed=()
for t in $THREADS; do
  for m in $MESHES; do
    p=$(path_of "$m")
    if [ ! -e "$p" ]; then
      echo "$p: not found (set RAYLAB_SHARED to the shared scenes folder)" >&2
      exit 1
    fi
    echo "== $m, $t thread(s)"
    if ! "$RAYLAB" bench "$p" --peers embree,obvhs,bvh --threads "$t" --repeats "$REPEATS" --resolution "$RESOLUTION" --json "$OUT/$m-t$t.json" 2>&1 | tee "$OUT/$m-t$t.md"; then
      failed+=("$m, $t thread(s)")
    fi
  done
done
echo "Tables and JSON in $OUT/."
if [ ${#failed[@]} -gt 0 ]; then
  printf 'FAILED (answers differ from the oracle beyond the tolerance): %s\n' "${failed[@]}" >&2
  exit 1
fi
