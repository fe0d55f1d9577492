#!/usr/bin/env bash
# Wall time and peak memory of the jobs that have targets (README.md,
# "Benchmarks"): the gate (at most 10 s), the quick report (at most 20 s) and
# the full nightly report (at most 180 s), on this machine with lavapipe.
# The reports go to a temporary folder and a temporary history database, so
# reports/history.sqlite is not touched. Usage: bench/tools/timings.sh [BUILD_DIR]
set -euo pipefail
build=${1:-build}
depthbench="$build/bench/depthbench"
[[ -x $depthbench ]] || { echo "no $depthbench: build first (see README.md)" >&2; exit 2; }
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

measure() {  # label, target seconds, then depthbench arguments
  local label=$1 target=$2; shift 2
  local log=$scratch/log
  /usr/bin/time -f '%e %M' -o "$scratch/time" "$depthbench" "$@" >"$log" 2>&1 || {
    local rc=$?
    [[ $rc -eq 1 ]] || { echo "$label failed (exit $rc):" >&2; tail -5 "$log" >&2; exit 1; }
  }
  read -r seconds kib <"$scratch/time"
  printf '%-34s %7.1f s (target %s s)  peak %4.0f MiB\n' "$label" "$seconds" "$target" "$((kib / 1024))"
}

echo "$(nproc) cores; $("$depthbench" list 2>/dev/null | grep -m1 -i llvmpipe || echo 'lavapipe')"
measure "gate (both baselines)" 10 gate --baseline reports/baselines/cpu.json --baseline reports/baselines/lavapipe.json
measure "report --quick" 20 report --quick --out "$scratch/quick" --history "$scratch/history.sqlite"
measure "report (full nightly)" 180 report --out "$scratch/full" --history "$scratch/history.sqlite"
