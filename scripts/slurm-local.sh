#!/bin/bash
# Proves the distributed render and benchmark sweep on a real Slurm: installs slurm-wlm, munge
# and jq from Debian, starts a one-node cluster on localhost (munged, slurmctld, slurmd; one
# partition of 2 CPUs) with its configuration, state and sockets in a temporary folder, then
#   render (deploy/slurm/submit.sh's sbatch files):
#   1. renders the path-traced Cornell box as a job array of tiles + a dependent merge job,
#      and compares the merged image byte for byte with a single-machine render;
#   2. times the same array run 1 and 2 tasks at a time (per-tile time and merge cost);
#   3. cancels one tile task mid-run, shows the merge cannot run, re-submits that index
#      alone (it resumes from its checkpoint) and merges: same bytes again;
#   bench (deploy/slurm/submit-bench.sh):
#   4. runs a sweep (the bunny and a generated Sierpinski tetrahedron, 4 structures, 3 ray
#      sets: 24 jobs) as 3 shard tasks + the dependent merge job, and compares the merged
#      JSON with an unsharded `raylab bench` of the same sweep in everything but timings;
#   5. cancels one shard mid-run, shows the merge cannot run, re-submits that index alone
#      and merges: the same JSON again;
# and finally stops the daemons it started (by their process ids) and removes its folder.
#
#   scripts/slurm-local.sh [--render] [--bench] [path/to/raylab]   (default: both parts,
#                                                                  target/release/raylab)
#
# It runs as root (to install packages); it touches no system configuration: the daemons
# read the configuration given on their command line (SLURM_CONF for the clients).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
parts=()
while [ $# -gt 0 ]; do
    case $1 in
        --render|--bench) parts+=("${1#--}"); shift ;;
        -*) echo "usage: $0 [--render] [--bench] [path/to/raylab]" >&2; exit 2 ;;
        *) break ;;
    esac
done
[ ${#parts[@]} -gt 0 ] || parts=(render bench)
raylab=$(realpath "${1:-$repo/target/release/raylab}")
[ -x "$raylab" ] || { echo "no raylab binary at $raylab (cargo build --release -p raylab)" >&2; exit 1; }
scene="$repo/scenes/cornell_path.toml"
size=(--width 96 --height 96 --spp 64 --pass-spp 8)
tiles=4

log() { printf '\n== %s\n' "$*"; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null || ! command -v jq >/dev/null; then
    log "installing slurm-wlm, munge and jq from Debian"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge jq >/dev/null
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

# The state and reason of a job that waits on a failed one, once Slurm has marked its
# dependency as never satisfied (at a scheduling pass after the failure; 30 s at most).
dependent_state() {
    local state
    for _ in $(seq 60); do
        state=$(squeue -h -j "$1" -o '%t %r' 2>/dev/null || true)
        [ "${state#* }" = DependencyNeverSatisfied ] && break
        sleep 0.5
    done
    echo "$state"
}

cd "$work/out"

render_part() {
    export RAYLAB="$raylab"
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
    echo "merge job state: $(dependent_state "$merge") (it cannot run: a tile failed)"
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
}

# A bench JSON without its timings (build_ms, mrays_per_s), which no two runs share.
without_timings() {
    jq -S 'walk(if type == "object" then del(.build_ms, .mrays_per_s) else . end)' "$1"
}

# Submits the sweep into folder $1 by deploy/slurm/submit-bench.sh; sets array and merge.
submit_bench() {
    local ids
    ids=$("$repo/deploy/slurm/submit-bench.sh" "$1" "$shards" "${scenes[@]}" -- "${sweep[@]}")
    echo "$ids"
    read -r array merge < <(sed -n 's/^shards: job \([0-9]*\), merge: job \([0-9]*\)$/\1 \2/p' <<<"$ids")
}

bench_part() {
    # The tasks run raylab through a wrapper that prints its wall time in the task's log: the
    # shard's or merge's own cost, apart from Slurm's scheduling and launch.
    cat > "$work/timed-raylab" <<WRAP
#!/bin/bash
TIMEFORMAT="raylab \$1: %R s wall"
time "$raylab" "\$@"
WRAP
    chmod +x "$work/timed-raylab"
    export RAYLAB="$work/timed-raylab"
    scenes=("$repo/scenes/bunny.toml" "$work/out/tetra.toml")
    sweep=(--accels bvh,bvh8,kdtree,grid --resolution 128 --repeats 3)
    shards=3

    log "unsharded bench of the sweep (1 thread, as each shard task has 1 CPU)"
    "$raylab" gen tetra --size 5 -o tetra.toml
    t0=$(date +%s.%N)
    "$raylab" bench "${scenes[@]}" "${sweep[@]}" --threads 1 --json-out whole.json --report whole.html >/dev/null
    t1=$(date +%s.%N)
    echo "unsharded bench: $(awk "BEGIN { printf \"%.2f\", $t1 - $t0 }") s wall, $(jq '.jobs.total' whole.json) jobs"

    log "the sweep as $shards shard tasks (2 at a time on 2 CPUs) + the dependent merge, by deploy/slurm/submit-bench.sh"
    t0=$(date +%s.%N)
    submit_bench bench
    wait_jobs "$array,$merge"
    t1=$(date +%s.%N)
    echo "array + merge: $(awk "BEGIN { printf \"%.2f\", $t1 - $t0 }") s wall"
    for ((i = 1; i <= shards; i++)); do
        echo "  shard $i: jobs $(jq -c '.jobs.ran' "bench/part-$i-of-$shards.json"), $(grep -h '^raylab bench:' "raylab-bench-${array}_$i.out")"
    done
    grep -h '^merged\|^raylab bench:' "raylab-bench-merge-$merge.out" | sed 's/^/  merge: /'
    without_timings whole.json > whole.untimed.json
    if without_timings "bench/part-1-of-$shards.json" | cmp -s whole.untimed.json -; then
        echo "the comparison cannot tell one part from the whole run" >&2
        exit 1
    fi
    if without_timings bench/bench.json | cmp -s whole.untimed.json -; then
        echo "RESULT: merged JSON of $shards Slurm shard tasks == unsharded bench, timings aside"
    else
        echo "RESULT: MISMATCH between the merged JSON and the unsharded bench:" >&2
        without_timings bench/bench.json | diff whole.untimed.json - | head -n 20 >&2
        exit 1
    fi

    log "cancelling one shard task mid-run, then re-submitting that index alone"
    dir=bench-cancel
    submit_bench "$dir"
    victim=2
    until [ "$(squeue -h -j "${array}_$victim" -o '%t' 2>/dev/null)" = R ]; do sleep 0.2; done
    sleep 1
    echo "cancelling task ${array}_$victim while it runs"
    scancel "${array}_$victim"
    while [ -n "$(squeue -h -t R,PD -j "$array" -o '%i' 2>/dev/null)" ]; do sleep 0.5; done
    sed 's/^/  task log: /' "raylab-bench-${array}_$victim.out" | tail -n 3
    echo "  task state: $(scontrol show job "${array}_$victim" | grep -o 'JobState=[A-Z_]*\|ExitCode=[0-9:]*' | tr '\n' ' ')"
    if [ -e "$dir/part-$victim-of-$shards.json" ]; then
        echo "the shard finished before it was cancelled: nothing shown" >&2
        exit 1
    fi
    echo "merge job state: $(dependent_state "$merge") (it cannot run: a shard failed)"
    scancel "$merge" 2>/dev/null || true
    ls -A "$dir"  # -A: a killed task leaves no hidden temporary file either
    redo=$(sbatch --parsable --array="$victim" "$repo/deploy/slurm/bench-shards.sbatch" "$dir" "$shards" "${scenes[@]}" -- "${sweep[@]}")
    merge=$(sbatch --parsable --dependency="afterok:$redo" "$repo/deploy/slurm/bench-merge.sbatch" "$dir" "$shards")
    echo "re-submitted index $victim as job $redo, merge job $merge"
    wait_jobs "$redo,$merge"
    grep -h '^raylab bench:' "raylab-bench-${redo}_$victim.out" | sed 's/^/  re-run shard: /'
    grep -h '^merged' "raylab-bench-merge-$merge.out"
    if without_timings "$dir/bench.json" | cmp -s whole.untimed.json -; then
        echo "RESULT: after cancelling shard $victim and re-running its index, merged JSON == unsharded bench, timings aside"
    else
        echo "RESULT: MISMATCH after the re-run" >&2
        exit 1
    fi
}

for part in "${parts[@]}"; do
    "${part}_part"
done
