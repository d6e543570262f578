#!/usr/bin/env bash
# The whole test suite on a busy machine: `cargo test --workspace` while 4 CPU-bound
# processes load every core, as on a studio PC doing other work or a shared CI runner.
# Real-time tests (ptys, the e-stop, liveness, a stopped simulator) must pass here too. Not
# part of CI.
#
#   tests/scripts/stress-test.sh [runs]             # default 1; docs/reliability.md reports 3 in a row
#   tests/scripts/stress-test.sh [runs] FILTER...   # only the root tests matching a filter,
#                                                   # e.g. `3 controller` (every real-time case
#                                                   # of the link: e-stop, claim, liveness, ptys)
set -euo pipefail
cd "$(dirname "$0")/../.."

runs=${1:-1}
shift || true
filters=("$@")
hogs=4
# The simulated form stopped mid-move (SIGSTOP for 0.5, 1.5 and 2.5 s) this many times per
# stop and link (tests/controller_liveness.rs; 2 without the script).
export DRESSFORM_STALL_TRIES=${DRESSFORM_STALL_TRIES:-20}

# Build first, unloaded: the load is for the tests, not the compiler.
cargo test --workspace --no-fail-fast --no-run

pids=()
stop_hogs() {
    for pid in "${pids[@]}"; do
        kill "$pid" 2>/dev/null || true
    done
    pids=()
}
trap stop_hogs EXIT

for run in $(seq 1 "$runs"); do
    for _ in $(seq 1 "$hogs"); do
        # A CPU-bound loop that does no I/O.
        sh -c 'while :; do :; done' &
        pids+=("$!")
    done
    echo "== run $run of $runs: cargo test ${filters[*]:---workspace} with $hogs CPU-bound" \
        "processes ($DRESSFORM_STALL_TRIES tries per simulator stop)"
    start=$(date +%s)
    if [ ${#filters[@]} -eq 0 ]; then
        tests=(cargo test --workspace --no-fail-fast)
    else
        tests=(cargo test --test main --no-fail-fast -- "${filters[@]}")
    fi
    if ! "${tests[@]}"; then
        echo "== run $run FAILED after $(( $(date +%s) - start )) s"
        exit 1
    fi
    echo "== run $run passed in $(( $(date +%s) - start )) s"
    stop_hogs
done
echo "== $runs of $runs runs passed"
