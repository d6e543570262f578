#!/usr/bin/env bash
# Runs every cargo-fuzz target of tests/fuzz for SECONDS each (default 600), seeded with
# tests/fuzz/seeds/<target>, with a 2 s per-input timeout and a 2 GB memory limit, and prints
# one line per target: runs, crashes, timeouts, out-of-memory, coverage, corpus size.
# Exit status 1 if any target did not run, or found a crash, a timeout or an out-of-memory
# input (kept in tests/fuzz/artifacts/<target>/). Needs `cargo install cargo-fuzz`; stable
# Rust is enough (RUSTC_BOOTSTRAP lets cargo-fuzz use the sanitizer flags).
#
# Usage: tests/scripts/fuzz.sh [SECONDS] [TARGET...]
set -uo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-600}
shift || true
export RUSTC_BOOTSTRAP=1
dir=(--fuzz-dir tests/fuzz)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || mapfile -t targets < <(cargo fuzz list "${dir[@]}")
cargo fuzz build "${dir[@]}" >/dev/null 2>&1 || { cargo fuzz build "${dir[@]}"; exit 1; }
failed=0
printf '%-10s %12s %8s %9s %5s %9s %7s\n' target runs crashes timeouts oom coverage corpus
for t in "${targets[@]}"; do
  corpus=tests/fuzz/corpus/$t
  artifacts=tests/fuzz/artifacts/$t
  mkdir -p "$corpus" "$artifacts"
  log=$(mktemp)
  cargo fuzz run "${dir[@]}" "$t" "$corpus" "tests/fuzz/seeds/$t" -- \
    -max_total_time="$seconds" -timeout=2 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$artifacts/" >"$log" 2>&1
  count() { find "$artifacts" -name "$1-*" | wc -l; }
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  printf '%-10s %12s %8s %9s %5s %9s %7s\n' "$t" "${runs:-?}" "$(count crash)" \
    "$(count timeout)" "$(count oom)" "${cov:-?}" "$(find "$corpus" -type f | wc -l)"
  # A target that did not run (unknown name, build failure) has no statistics: a failure too.
  if [ -z "$runs" ] || [ "$(count crash)" != 0 ] || [ "$(count timeout)" != 0 ] ||
    [ "$(count oom)" != 0 ]; then
    failed=1
    tail -40 "$log"
  fi
  rm -f "$log"
done
exit $failed
