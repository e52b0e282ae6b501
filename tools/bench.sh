#!/usr/bin/env bash
# Speed figures of the offline runner: per-stage ms as the paper's Table V, FPS, peak memory.
#  1. The CPU backend's scaling on the 60 real HDL-64E scans, frame-to-model: FPS and each stage's
#     median at 1, 2 and all threads (BENCH_THREADS, e.g. "1 2 4 8 all"), and each stage's parallel
#     speed-up over 1 thread. Each setting runs BENCH_REPEAT times (default 3) and keeps each stage's
#     fastest median, so that other load on the machine shows less.
#  2. The CPU backend, frame-to-frame, with 1 and 2 threads, on the same scans.
#  3. Both backends on the same scans, the real ones and a simulated urban drive, frame-to-model, the CPU
#     with all its threads. The CUDA runs also print what of the scans' upload to the GPU the frames
#     waited for (elo_run prefetches each scan while the one before it runs) and the FPS without it. Where the CUDA backend cannot run, they are left out, saying why.
# Usage:
#   tools/bench.sh BUILD_DIR SHARED_DATA_DIR
# BUILD_DIR may also be the directory of the executables themselves (a kit packed by gpu_kit.sh).
# BENCH_SCANS replaces the real scans of parts 1 and 2 by another sequence (e.g. one elo_sim wrote).
set -euo pipefail
build=${1:-build}
data=${2:-../shared/data}
bin="$build/devel/lib/elo_odometry"
[ -x "$bin/elo_run" ] || bin=$build
scans=${BENCH_SCANS:-$data/real/hdl64_drive_a}  # the scaling and f2f runs' scans
thread_settings=${BENCH_THREADS:-1 2 all}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

run() {  # elo_run over $1 with the other arguments, printing its summary
  local input=$1
  shift
  "$bin/elo_run" --input "$input" --output "$out/poses.txt" --quiet "$@" | sed -n '/^stage/,$p'
}

# The number of scans in a sequence directory: a KITTI-style one's velodyne/*.bin, else its files.
scan_count() {
  if [ -d "$1/velodyne" ]; then ls "$1/velodyne" | wc -l; else ls "$1" | wc -l; fi
}

# scaling: the frame-to-model scaling table of the CPU backend over $scans (see the top).
scaling() {
  local repeat=${BENCH_REPEAT:-3} threads run_index
  echo "=== CPU, f2m, scaling over threads, $(basename "$scans") ($(scan_count "$scans") scans), fastest of $repeat runs"
  for threads in $thread_settings; do
    for run_index in $(seq "$repeat"); do
      local option=()
      [ "$threads" != all ] && option=(--threads "$threads")
      "$bin/elo_run" --input "$scans" --output "$out/poses.txt" --quiet --mode f2m "${option[@]}" \
        --timing "$out/timing_${threads}_${run_index}.csv" >/dev/null
    done
  done
  python3 - "$out" "$repeat" "$(nproc)" $thread_settings <<'PYTHON'
import csv, statistics, sys
out, repeat, cores, settings = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4:]
stages = [("spherical projection", "projection_ms"), ("feature extraction", "features_ms"),
          ("ICP optimization", "registration_ms"), ("model update", "model_update_ms"), ("total", "total_ms")]
def fastest(threads, column):  # each run's median over the processed frames; the fastest run's
    medians = []
    for run in range(1, repeat + 1):
        with open(f"{out}/timing_{threads}_{run}.csv") as f:
            rows = [r for r in csv.DictReader(f) if r["processed"] == "1"]
        # The first frame is not registered: the registration median is over the registered frames.
        values = [float(r[column]) for r in rows if column != "registration_ms" or int(r["iterations"]) > 0]
        medians.append(statistics.median(values))
    return min(medians)
table = {s: {t: fastest(t, c) for t in settings} for s, c in stages}
names = {t: f"all ({cores})" if t == "all" else (f"{t} thread" if t == "1" else f"{t} threads") for t in settings}
others = [t for t in settings if t != settings[0]]
print(f"{'median ms':<22}" + "".join(f" {names[t]:>10}" for t in settings) +
      "".join(f" {'speed-up ' + t:>13}" for t in others))
for name, _ in stages:
    row = table[name]
    print(f"{name:<22}" + "".join(f" {row[t]:10.2f}" for t in settings) +
          "".join(f" {row[settings[0]] / row[t]:12.2f}x" for t in others))
def fastest_mean_total(threads):
    means = []
    for run in range(1, repeat + 1):
        with open(f"{out}/timing_{threads}_{run}.csv") as f:
            means.append(statistics.mean(float(r["total_ms"]) for r in csv.DictReader(f) if r["processed"] == "1"))
    return min(means)
fps = {t: 1000.0 / fastest_mean_total(t) for t in settings}  # as elo_run's pipeline FPS: 1000 / mean total
print(f"{'FPS':<22}" + "".join(f" {fps[t]:10.1f}" for t in settings) +
      "".join(f" {fps[t] / fps[settings[0]]:12.2f}x" for t in others))
PYTHON
}

if [ -d "$scans" ]; then
  scaling
  for threads in 1 2; do
    echo "=== CPU, f2f, $threads thread(s), $(basename "$scans") ($(scan_count "$scans") scans)"
    run "$scans" --mode f2f --threads "$threads"
  done
else
  echo "bench: no real scans at $scans (shared data absent); only the simulated drive is measured" >&2
fi

frames=200
echo "=== simulating $frames HDL-64E scans of an urban drive (seed 1)"
"$bin/elo_sim" --world urban --trajectory curves --frames "$frames" --seed 1 --sensor hdl64 \
  --output "$out/simulated" >/dev/null
inputs=("$out/simulated")
[ -d "$scans" ] && inputs=("$scans" "${inputs[@]}")

# Loading every kernel when the CUDA context starts keeps module loading out of the first frame's time.
export CUDA_MODULE_LOADING=EAGER
backends=(cpu cuda)
if ! problem=$("$bin/elo_run" --input "$out/simulated" --output "$out/poses.txt" --frames 1 --quiet --backend cuda 2>&1 >/dev/null); then
  echo "bench: the CUDA backend is left out (${problem#elo_run: })" >&2
  backends=(cpu)
fi
for input in "${inputs[@]}"; do
  for backend in "${backends[@]}"; do
    echo "=== $backend backend, f2m, all threads, $(basename "$input")"
    run "$input" --mode f2m --backend "$backend"
  done
done
