#!/bin/bash
# Submits a frame as N tile tasks and the merge that waits for them:
#
#   deploy/slurm/submit.sh SCENE OUTDIR N IMAGE [raylab render options...]
#
# Prints the two job ids. The merge runs only if every tile succeeds (afterok); see
# docs/distributed.md for re-running a failed tile.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
scene=${1:?scene} outdir=${2:?output folder} tiles=${3:?tiles} image=${4:?image}
shift 4
mkdir -p "$outdir"
array=$(sbatch --parsable --array="0-$((tiles - 1))" "$here/render-tiles.sbatch" "$scene" "$outdir" "$tiles" "$@")
merge=$(sbatch --parsable --dependency="afterok:$array" "$here/merge.sbatch" "$outdir" "$tiles" "$image")
echo "tiles: job $array, merge: job $merge"
