#!/usr/bin/env bash
# Throughput and memory of `depthbench run` end to end: verified
# reconstructions per second and the peak resident memory, which must not
# grow with the sample count.
#
#   bench/tools/throughput.sh [BUILD_DIR] [RUNS] [DEVICE] [ROWS]
#
# Without DEVICE: the CPU backend at 10^6, 10^7 and 10^8 samples, and
# lavapipe with either judge (--judge host: outputs read back and binned on
# the host's cores; --judge device: binned where they are). With DEVICE (a
# part of a Vulkan device's name, as --device takes it, "nvidia"): that
# device with either judge at 10^7 and 10^8 samples, and with its own
# judge at 10^9, each in its default batches (and at 10^9 with the
# reconstruction pass apart from the judge's, --judge-fusion separate).
# Each ends with the raster form (--pipeline raster) beside the compute
# form with the same judge and samples, so that the two rates compare: on
# lavapipe judged on the host, on DEVICE with either judge. DEPTHBENCH names another program to run (a packed copy's
# run.sh, bench/tools/package_for_device.sh).
#
# ROWS, an extended regular expression, keeps only the configurations
# whose label matches it ("form" keeps the compute and raster rows).
#
# Each configuration runs RUNS times (default 3), the configurations in
# turn (A B C ... A B C ...), so that the drift of a shared machine's speed
# falls on all of them alike. A row gives the median rate, the range of
# the runs, and the largest peak. Last, for scale, the bare reconstruction
# kernel on the same Vulkan device (`depthbench speed`: its fastest
# memory-bound full-screen pass, divide/reversed/d32_sfloat reading a
# 3840x2160 depth image, nothing judged), and each Vulkan row's median as
# a share of it.
set -euo pipefail
build=${1:-build}
runs=${2:-3}
device=${3:-}
depthbench=${DEPTHBENCH:-$build/bench/depthbench}
[[ -x $depthbench ]] || { echo "no $depthbench: build first (see README.md)" >&2; exit 2; }
[[ $runs =~ ^[1-9][0-9]*$ ]] || { echo "RUNS must be a whole number of at least 1, not '$runs'" >&2; exit 2; }

if [[ -z $device ]]; then
  labels=(
    "cpu backend, 1e6 samples (106 cells)"
    "cpu backend, 1e7 samples"
    "cpu backend, 1e8 samples"
    "lavapipe, host judge, 1e6 samples"
    "lavapipe, host judge, 1e7 samples"
    "lavapipe, device judge, 1e6 samples"
    "lavapipe, compute form, host judge, 1e5"
    "lavapipe, raster form, host judge, 1e5"
  )
  arguments=(
    "--backend cpu --samples 1e6"
    "--backend cpu --samples 1e7"
    "--backend cpu --samples 1e8"
    "--backend vulkan --judge host --samples 1e6"
    "--backend vulkan --judge host --samples 1e7"
    "--backend vulkan --judge device --samples 1e6"
    "--backend vulkan --judge host --pipeline compute --samples 1e5"
    "--backend vulkan --judge host --pipeline raster --samples 1e5"
  )
else
  labels=() arguments=()
  for samples in 1e7 1e8; do
    for judge in host device; do
      labels+=("$device, $judge judge, $samples samples")
      arguments+=("--backend vulkan --device $device --judge $judge --samples $samples")
    done
  done
  # And the device judge over a sweep long enough that a run's fixed
  # costs (its set-up, its first and last batches) fade.
  # Fused (the default on a GPU) and with the reconstruction apart.
  labels+=("$device, device judge, 1e9 samples")
  arguments+=("--backend vulkan --device $device --judge device --samples 1e9")
  labels+=("$device, device judge, separate passes, 1e9 samples")
  arguments+=("--backend vulkan --device $device --judge device --judge-fusion separate --samples 1e9")
  for judge in host device; do
    for form in compute raster; do
      labels+=("$device, $form form, $judge judge, 1e7")
      arguments+=("--backend vulkan --device $device --judge $judge --pipeline $form --samples 1e7")
    done
  done
fi
rows=${4:-}
if [[ -n $rows ]]; then
  kept_labels=() kept_arguments=()
  for i in "${!labels[@]}"; do
    if grep -Eq -- "$rows" <<<"${labels[i]}"; then
      kept_labels+=("${labels[i]}")
      kept_arguments+=("${arguments[i]}")
    fi
  done
  ((${#kept_labels[@]} > 0)) || { echo "no configuration's label matches ROWS '$rows'" >&2; exit 2; }
  labels=("${kept_labels[@]}") arguments=("${kept_arguments[@]}")
fi
declare -a rates peaks  # per configuration: space-separated figures of its runs

log=$(mktemp)
trap 'rm -f "$log"' EXIT
for ((r = 1; r <= runs; ++r)); do
  for i in "${!labels[@]}"; do
    echo "run $r of $runs: ${labels[i]}" >&2
    # shellcheck disable=SC2086  # the arguments are words on purpose
    /usr/bin/time -v "$depthbench" run --quiet ${arguments[i]} >"$log" 2>&1 ||
      { cat "$log" >&2; exit 1; }
    # "... verified in 12.38 s: 85.65M/s": the rate, in millions per second.
    rate=$(grep -o 'verified in [0-9.]* s: [0-9.]*[kMG]*/s' "$log" |
      awk '{r = $5; u = substr(r, length(r) - 2, 1); v = r + 0
            printf "%.1f", u == "G" ? v * 1000 : u == "M" ? v : u == "k" ? v / 1000 : v / 1e6}') ||
      { echo "no 'verified in' line in the output of run ${arguments[i]}:" >&2; cat "$log" >&2; exit 1; }
    rates[i]+="$rate "
    # Where the time went (the build, the judging, the waits), run by run.
    # (and, where a device judged, its seconds per pass, over two lines).
    awk '/^time:/ {print} /^device passes:/ {print; more = 1; next} more && /^  / {print} {more = 0}' "$log" >&2
    peaks[i]+="$(awk '/Maximum resident set size/ {printf "%.0f ", $6 / 1024}' "$log")"
  done
done

# The bare kernel (see the top): lavapipe's in its quick form, whose
# fewer repetitions are plenty at a CPU's pace.
echo "speed: the bare reconstruction kernel on ${device:-lavapipe}" >&2
kernel_json=$(mktemp)
trap 'rm -f "$log" "$kernel_json"' EXIT
quick=()
[[ -z $device ]] && quick=(--quick)
"$depthbench" speed --quiet ${device:+--device "$device"} "${quick[@]}" --variant divide --convention reversed \
  --format d32f --resolution 3840x2160 --json "$kernel_json" >"$log" 2>&1 || { cat "$log" >&2; exit 1; }
kernel=$(python3 -c '
import json, sys
passes = [p for p in json.load(open(sys.argv[1]))["gpu"] if p["regime"] == "memory"]
print("%.1f" % (1e3 / min(p["ns_per_reconstruction"] for p in passes)))' "$kernel_json") ||
  { echo "no memory-bound pass in the speed results" >&2; exit 1; }

printf '%-40s %22s %12s %10s\n' "" "M reconstructions/s" "peak MiB" "of kernel"
printf '%-40s %22s %12s %10s\n' "" "median (min-max)" "(largest)" ""
for i in "${!labels[@]}"; do
  summary=$(tr ' ' '\n' <<<"${rates[i]}" | grep . | sort -g |
    awk '{v[NR] = $1} END {m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
                           printf "%.1f (%.1f-%.1f)", m, v[1], v[NR]}')
  peak=$(tr ' ' '\n' <<<"${peaks[i]}" | grep . | sort -g | tail -1)
  share=""
  if [[ ${arguments[i]} == *"--backend vulkan"* ]]; then
    share=$(awk -v m="${summary%% *}" -v k="$kernel" 'BEGIN {printf "%.2f%%", 100 * m / k}')
  fi
  printf '%-40s %22s %12s %10s\n' "${labels[i]}" "$summary" "$peak" "$share"
done
printf '%-40s %22s\n' "bare kernel (speed, memory-bound)" "$kernel"
