#!/bin/bash
# Proves the distributed render on a real Slurm: installs slurm-wlm and munge from Debian,
# starts a one-node cluster on localhost (munged, slurmctld, slurmd; one partition of 2
# CPUs) with its configuration, state and sockets in a temporary folder, then
#   1. renders the path-traced Cornell box as a job array of tiles + a dependent merge job,
#      and compares the merged image byte for byte with a single-machine render;
#   2. times the same array run 1 and 2 tasks at a time (per-tile time and merge cost);
#   3. cancels one tile task mid-run, shows the merge cannot run, re-submits that index
#      alone (it resumes from its checkpoint) and merges: same bytes again;
# and finally stops the daemons it started (by their process ids) and removes its folder.
#
#   scripts/slurm-local.sh [path/to/raylab]      (default: target/release/raylab)
#
# It runs as root (to install packages); it touches no system configuration: the daemons
# read the configuration given on their command line (SLURM_CONF for the clients).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
raylab=$(realpath "${1:-$repo/target/release/raylab}")
[ -x "$raylab" ] || { echo "no raylab binary at $raylab (cargo build --release -p raylab)" >&2; exit 1; }
scene="$repo/scenes/cornell_path.toml"
size=(--width 96 --height 96 --spp 64 --pass-spp 8)
tiles=4

log() { printf '\n== %s\n' "$*"; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    log "installing slurm-wlm and munge from Debian"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi

work=$(mktemp -d /tmp/raylab-slurm.XXXXXX)
chmod 700 "$work"
pids=()
cleanup() {
    set +e
    log "cleaning up: cancelling our jobs, stopping the daemons we started (${pids[*]:-none}), removing $work"
    if [ -n "${SLURM_CONF:-}" ] && [ -S "$work/munge.sock" ]; then
        scancel --user="$(id -un)" 2>/dev/null
    fi
    for pid in "${pids[@]}"; do
        kill "$pid" 2>/dev/null
    done
    for pid in "${pids[@]}"; do
        for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$pid" 2>/dev/null
    done
    rm -rf "$work"
}
trap cleanup EXIT

log "starting munged with its own key and socket in $work"
dd if=/dev/urandom of="$work/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/munge.key"
munged --force --key-file="$work/munge.key" --socket="$work/munge.sock" --pid-file="$work/munged.pid" \
    --log-file="$work/munged.log" --seed-file="$work/munged.seed"
for _ in $(seq 50); do [ -s "$work/munged.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$work/munged.pid")")

node=$(hostname -s)
mkdir -p "$work/state" "$work/spool" "$work/out"
cat > "$work/slurm.conf" <<CONF
ClusterName=raylab-local
SlurmctldHost=$node(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge.sock
SlurmctldPort=16817
SlurmdPort=16818
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
KillWait=30
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=$node NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=local Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf"

log "starting slurmctld and slurmd (node $node, 2 CPUs)"
slurmctld -f "$SLURM_CONF"
for _ in $(seq 100); do [ -s "$work/slurmctld.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$work/slurmctld.pid")")
slurmd -f "$SLURM_CONF"
for _ in $(seq 100); do [ -s "$work/slurmd.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$work/slurmd.pid")")
for _ in $(seq 100); do
    sinfo -h -o '%t' 2>/dev/null | grep -qE '^(idle|mix|alloc)' && break
    sleep 0.2
done
sinfo

# Waits until none of the given jobs is pending or running.
wait_jobs() {
    while [ -n "$(squeue -h -j "$1" -o '%i' 2>/dev/null)" ]; do sleep 0.5; done
}

export RAYLAB="$raylab"
cd "$work/out"

log "single-machine render (2 threads)"
t0=$(date +%s.%N)
"$raylab" render "$scene" "${size[@]}" --threads 2 -o single.exr
t1=$(date +%s.%N)
echo "single render: $(awk "BEGIN { printf \"%.2f\", $t1 - $t0 }") s wall"

for concurrency in 1 2; do
    log "job array of $tiles tiles, at most $concurrency task(s) at a time, then the dependent merge"
    dir="run$concurrency"
    mkdir -p "$dir"
    t0=$(date +%s.%N)
    array=$(sbatch --parsable --array="0-$((tiles - 1))%$concurrency" "$repo/deploy/slurm/render-tiles.sbatch" "$scene" "$dir" "$tiles" "${size[@]}")
    merge=$(sbatch --parsable --dependency="afterok:$array" "$repo/deploy/slurm/merge.sbatch" "$dir" "$tiles" "$dir/merged.exr")
    echo "array job $array, merge job $merge"
    wait_jobs "$array,$merge"
    t1=$(date +%s.%N)
    echo "array + merge: $(awk "BEGIN { printf \"%.2f\", $t1 - $t0 }") s wall"
    grep -ho 'Traced .* rays in [0-9.]* s' raylab-tiles-"$array"_*.out | sed 's/^/  tile: /'
    grep -h 'Merged' raylab-merge-"$merge".out
    if cmp -s single.exr "$dir/merged.exr"; then
        echo "RESULT: merged image of $tiles Slurm tasks == single render, byte for byte"
    else
        echo "RESULT: MISMATCH between the merged image and the single render" >&2
        exit 1
    fi
done

log "cancelling one tile task mid-run, then re-submitting that index alone"
dir=cancel
mkdir -p "$dir"
# More samples so that the task is still running when it is cancelled; checkpoints every pass.
long=(--width 96 --height 96 --spp 512 --pass-spp 8)
"$raylab" render "$scene" "${long[@]}" --threads 2 -o single-long.exr --quiet
array=$(CHECKPOINT_EVERY=0 sbatch --export=ALL --parsable --array="0-$((tiles - 1))" "$repo/deploy/slurm/render-tiles.sbatch" "$scene" "$dir" "$tiles" "${long[@]}")
merge=$(sbatch --parsable --dependency="afterok:$array" "$repo/deploy/slurm/merge.sbatch" "$dir" "$tiles" "$dir/merged.exr")
victim=1
until [ "$(squeue -h -j "${array}_$victim" -o '%t' 2>/dev/null)" = R ] && [ -f "$dir/tile-$victim-of-$tiles.ckpt" ]; do sleep 0.2; done
sleep 1
echo "cancelling task ${array}_$victim while it runs"
scancel "${array}_$victim"
while [ -n "$(squeue -h -t R,PD -j "$array" -o '%i' 2>/dev/null)" ]; do sleep 0.5; done
sed 's/^/  task log: /' "raylab-tiles-${array}_$victim.out" | tail -n 3
echo "merge job state: $(squeue -h -j "$merge" -o '%t %r' 2>/dev/null || true) (it cannot run: a tile failed)"
scancel "$merge" 2>/dev/null || true
ls "$dir"
redo=$(CHECKPOINT_EVERY=0 sbatch --export=ALL --parsable --array="$victim" "$repo/deploy/slurm/render-tiles.sbatch" "$scene" "$dir" "$tiles" "${long[@]}")
merge=$(sbatch --parsable --dependency="afterok:$redo" "$repo/deploy/slurm/merge.sbatch" "$dir" "$tiles" "$dir/merged.exr")
echo "re-submitted index $victim as job $redo, merge job $merge"
wait_jobs "$redo,$merge"
grep -h 'resuming' "raylab-tiles-${redo}_$victim.out" || true
grep -h 'Merged' "raylab-merge-$merge.out"
if cmp -s single-long.exr "$dir/merged.exr"; then
    echo "RESULT: after cancelling task $victim and re-running its index, merged == single render, byte for byte"
else
    echo "RESULT: MISMATCH after the re-run" >&2
    exit 1
fi
