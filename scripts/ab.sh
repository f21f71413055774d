#!/usr/bin/env bash
# Alternated A/B pairs of `raylab trace` on one ray file: the geometric mean of B/A over N
# pairs, with a two-sigma interval, so that a change of a few per cent can be told from the
# noise of a shared machine (docs/performance.md, twenty-fourth round: one process against
# another of the same binary spreads by ±12 %, so medians of 7-11 pairs cannot show 3 %).
#
#   scripts/ab.sh [-n PAIRS] A_CMD B_CMD -- TRACE_ARGS...
#
# A_CMD and B_CMD are a binary each with optional flags of its own (one word each, quoted
# together), e.g. two builds, or one build with two settings:
#
#   scripts/ab.sh -n 30 "target/release/raylab --prefetch off" "target/release/raylab --prefetch on" -- \
#     ../shared/scenes/dragon_vrip.obj.gz --rays rays/dragon_vrip-diffuse.rays --accel bvh8 --threads 1 --repeats 15
#
# Each pair runs A then B, or B then A in every other pair. Prints one line:
#   B/A 1.079 [1.034, 1.126]  A 2.19 B 2.36 Mrays/s  n=30
set -euo pipefail
pairs=20
if [ "${1:-}" = "-n" ]; then pairs=$2; shift 2; fi
[ $# -ge 3 ] && [ "$3" = "--" ] || { sed -n '2,15p' "$0" >&2; exit 2; }
a_cmd=$1 b_cmd=$2
shift 3

mrays() {
    local bin=${1%% *} flags=""
    [ "$bin" != "$1" ] && flags=${1#* }
    # shellcheck disable=SC2086 # the flags are words
    "$bin" trace "${@:2}" $flags | grep -o '[0-9.]* Mrays/s' | cut -d' ' -f1
}

for i in $(seq "$pairs"); do
    if [ $((i % 2)) = 0 ]; then a=$(mrays "$a_cmd" "$@"); b=$(mrays "$b_cmd" "$@"); else b=$(mrays "$b_cmd" "$@"); a=$(mrays "$a_cmd" "$@"); fi
    echo "$a $b"
done | python3 -c '
import math, sys
pairs = [tuple(map(float, l.split())) for l in sys.stdin if l.strip()]
logs = [math.log(b / a) for a, b in pairs]
n = len(logs)
mean = sum(logs) / n
se = (sum((x - mean) ** 2 for x in logs) / max(n - 1, 1)) ** 0.5 / n ** 0.5
geo = lambda k: math.exp(sum(math.log(p[k]) for p in pairs) / n)
print(f"B/A {math.exp(mean):.3f} [{math.exp(mean - 2 * se):.3f}, {math.exp(mean + 2 * se):.3f}]  A {geo(0):.2f} B {geo(1):.2f} Mrays/s  n={n}")
'
