#!/usr/bin/env bash
# Mutation testing (cargo-mutants) per crate, each against its own tests, within a time
# budget. Not part of CI: a full pass takes hours. Results go to target/mutants/<crate>/ and a
# one-line summary per crate is printed; copy the figures into docs/testing.md.
#
#   cargo install cargo-mutants                 # once
#   scripts/mutants.sh                          # every math-heavy crate
#   scripts/mutants.sh raylab-core              # one crate
#   MUTANTS_FILES='crates/core/src/sampling.rs' MUTANTS_BUDGET=1800 scripts/mutants.sh raylab-core
#
# MUTANTS_BUDGET: seconds per crate (default 3600); when it runs out the crate's run stops
# and the summary covers the mutants tried so far. MUTANTS_TIMEOUT: seconds one mutant's
# tests may take before counting as "timeout" (default 120). MUTANTS_FILES: only mutate
# these files (space-separated paths or globs). MUTANTS_JOBS: parallel builds (default 1).
# MUTANTS_OUT: results folder (default target/mutants). MUTANTS_ITERATE=1: re-test only
# the mutants not caught by the previous run into the same folder (after adding tests); the
# summary then counts the re-tested mutants only. MUTANTS_TEST_ARGS: which of the crate's
# test targets to build and run, space-separated cargo arguments, each passed to every cargo
# invocation as one `--cargo-arg` (`--cargo-test-arg` would reach `cargo test` but not the
# `cargo test --no-run` build before it, which would still build every target). E.g.
# MUTANTS_TEST_ARGS='--lib' builds and runs only the crate's unit tests: for `raylab-render` a
# mutant then costs one build of the library instead of one per integration test binary. Use
# it for a fast first pass, then re-test the missed mutants with MUTANTS_ITERATE=1 and no
# test args, so that the rates reported are against the crate's full tests.
set -euo pipefail
cd "$(dirname "$0")/.."

command -v cargo-mutants >/dev/null || { echo "scripts/mutants.sh: cargo-mutants is not installed (cargo install cargo-mutants)" >&2; exit 2; }
budget=${MUTANTS_BUDGET:-3600}
timeout_s=${MUTANTS_TIMEOUT:-120}
jobs=${MUTANTS_JOBS:-1}
crates=("$@")
[ ${#crates[@]} -gt 0 ] || crates=(raylab-core raylab-accel raylab-render raylab-loader raylab-procedural)
files=()
for f in ${MUTANTS_FILES:-}; do files+=(--file "$f"); done
[ -z "${MUTANTS_ITERATE:-}" ] || files+=(--iterate)
for a in ${MUTANTS_TEST_ARGS:-}; do files+=("--cargo-arg=$a"); done

count() { [ -f "$1" ] && wc -l <"$1" | tr -d ' ' || echo 0; }

for crate in "${crates[@]}"; do
    out="${MUTANTS_OUT:-target/mutants}/$crate"
    mkdir -p "$out"
    start=$(date +%s)
    # Exit codes 2 (missed mutants) and 3 (timeouts) are results, not failures; 124 = budget spent.
    status=0
    timeout --signal=INT "$budget" cargo mutants --package "$crate" --timeout "$timeout_s" --jobs "$jobs" --output "$out" "${files[@]}" >"$out/log.txt" 2>&1 || status=$?
    dir="$out/mutants.out"
    caught=$(count "$dir/caught.txt"); missed=$(count "$dir/missed.txt"); timeouts=$(count "$dir/timeout.txt"); unviable=$(count "$dir/unviable.txt")
    tried=$((caught + missed + timeouts + unviable))
    viable=$((caught + missed + timeouts))
    rate=$([ "$viable" -gt 0 ] && awk "BEGIN { printf \"%.1f\", 100 * $caught / $viable }" || echo "-")
    note=$([ "$status" -eq 124 ] && echo " (budget of ${budget}s spent: partial)" || echo "")
    echo "$crate: tried $tried, caught $caught, missed $missed, timed out $timeouts, unviable $unviable; caught $rate % of viable in $(( $(date +%s) - start ))s$note"
    [ "$missed" -eq 0 ] || { echo "  missed:"; sed 's/^/    /' "$dir/missed.txt"; }
done
