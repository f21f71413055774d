#!/bin/bash
# Submits a benchmark sweep as N shard tasks and the merge that waits for them:
#
#   deploy/slurm/submit-bench.sh OUTDIR N SCENES... [-- raylab bench options...]
#
# Prints the two job ids. The merge runs only if every shard succeeds (afterok); see
# docs/distributed.md for re-running a failed shard.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
outdir=${1:?output folder} shards=${2:?shards}
shift 2
mkdir -p "$outdir"
array=$(sbatch --parsable --array="1-$shards" "$here/bench-shards.sbatch" "$outdir" "$shards" "$@")
merge=$(sbatch --parsable --dependency="afterok:$array" "$here/bench-merge.sbatch" "$outdir" "$shards")
echo "shards: job $array, merge: job $merge"
