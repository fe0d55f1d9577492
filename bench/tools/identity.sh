#!/usr/bin/env bash
# Writes what fixed-seed runs say, minus what may differ between two runs
# of one build (the `run` block: times, host, commit), so that two builds
# can be compared byte for byte: a change that restructures code without
# meaning to change a result must leave every file identical.
#   bench/tools/identity.sh BUILD_DIR OUT_DIR
#   diff -r OUT_DIR_BEFORE OUT_DIR_AFTER   (no output: the same results)
# It covers the CPU and lavapipe, the compute and raster forms, the host and
# device judges (drawing on the device and on the host), the three preset
# domains, a user's variant file, a shard merge, and the gate against both
# committed baselines. About three minutes on 2 cores.
set -euo pipefail
build=${1:?usage: identity.sh BUILD_DIR OUT_DIR}
out=${2:?usage: identity.sh BUILD_DIR OUT_DIR}
depthbench="$build/bench/depthbench"
[[ -x $depthbench ]] || { echo "no $depthbench: build first (see README.md)" >&2; exit 2; }
mkdir -p "$out"
raw=$(mktemp -d)
trap 'rm -rf "$raw"' EXIT

# A results document without its `run` block, keys sorted, one per line.
strip_run() {
  python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); d.pop("run",None); json.dump(d,sys.stdout,indent=1,sort_keys=True)' "$1" >"$2"
}

# name, then depthbench run arguments
run_case() {
  local name=$1; shift
  echo "identity: $name" >&2
  "$depthbench" run --quiet --seed 7 "$@" --json "$raw/$name.json" >/dev/null
  strip_run "$raw/$name.json" "$out/$name.json"
}

run_case cpu-typical --backend cpu --samples 3e5
run_case cpu-wide --backend cpu --domain wide --samples 2e5
run_case cpu-extremes --backend cpu --domain extremes --samples 2e5
run_case cpu-distance-bands --backend cpu --camera-distance 0:1e5 --samples 1e5
run_case lavapipe-host-judge --backend vulkan --judge host --samples 2e5
run_case lavapipe-device-judge --backend vulkan --judge device --samples 5e4
run_case lavapipe-device-judge-host-draws --backend vulkan --judge device --draw host --domain wide --samples 5e4
run_case raster-cpu-lavapipe --backend cpu,vulkan --pipeline raster --samples 1e4
run_case user-variant --variant-file bench/examples/divide_subtract_first.glsl --samples 5e4
run_case shard-1 --backend cpu --samples 1e5 --shard 1/2
run_case shard-2 --backend cpu --samples 1e5 --shard 2/2
"$depthbench" merge "$raw/shard-1.json" "$raw/shard-2.json" --json "$raw/merged.json" >/dev/null
strip_run "$raw/merged.json" "$out/merged.json"

# The gate: its verdict, its table, its full comparison and its JUnit
# report (times removed).
echo "identity: gate" >&2
rc=0
"$depthbench" gate --baseline reports/baselines/cpu.json --baseline reports/baselines/lavapipe.json \
  --junit "$raw/gate.xml" --json "$raw/gate.json" >"$raw/gate.txt" 2>&1 || rc=$?
echo "exit $rc" >"$out/gate.txt"
sed -E 's/ \([0-9.]+ s\)//' "$raw/gate.txt" >>"$out/gate.txt"
sed -E 's/ time="[^"]*"//g; s/ timestamp="[^"]*"//g; s/ hostname="[^"]*"//g' "$raw/gate.xml" >"$out/gate.xml"
strip_run "$raw/gate.json" "$out/gate.json"
echo "identity: wrote $(ls "$out" | wc -l) files to $out" >&2
