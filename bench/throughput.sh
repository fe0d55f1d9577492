#!/usr/bin/env bash
# Throughput and memory of `depthbench run` end to end: verified
# reconstructions per second on the CPU backend and on lavapipe, and the
# peak resident memory for 10^6 and 10^8 samples (it must not grow with the
# sample count). Usage: bench/throughput.sh [BUILD_DIR]
set -euo pipefail
build=${1:-build}
depthbench="$build/bench/depthbench"
[[ -x $depthbench ]] || { echo "no $depthbench: build first (see README.md)" >&2; exit 2; }

measure() {  # label, then depthbench arguments
  local label=$1; shift
  local log; log=$(mktemp)
  /usr/bin/time -v "$depthbench" run --quiet "$@" >"$log" 2>&1
  local rate peak
  rate=$(grep -o 'verified in [0-9.]* s: [0-9.]*[kMG]*/s' "$log" | sed 's/.*: //')
  peak=$(awk '/Maximum resident set size/ {printf "%.0f MiB", $6 / 1024}' "$log")
  printf '%-44s %14s reconstructions  peak %s\n' "$label" "$rate" "$peak"
  rm -f "$log"
}

measure "cpu backend, 1e6 samples (106 cells)" --backend cpu --samples 1e6
measure "cpu backend, 1e7 samples" --backend cpu --samples 1e7
measure "cpu backend, 1e8 samples" --backend cpu --samples 1e8
measure "lavapipe, 1e6 samples (106 cells)" --backend vulkan --samples 1e6
measure "lavapipe, 1e7 samples" --backend vulkan --samples 1e7
