#!/usr/bin/env bash
# Speed figures of the offline runner: per-stage ms as the paper's Table V, FPS, peak memory.
#  1. The CPU backend, frame-to-model and frame-to-frame, with 1 and 2 threads, on the 60 real HDL-64E
#     scans.
#  2. Both backends on the same scans, the real ones and a simulated urban drive, frame-to-model, the CPU
#     with all its threads. The CUDA runs also print the scan's upload to the GPU (part of the projection)
#     and the FPS without it. Where the CUDA backend cannot run, they are left out, saying why.
# Usage:
#   tools/bench.sh BUILD_DIR SHARED_DATA_DIR
set -euo pipefail
build=${1:-build}
data=${2:-../shared/data}
bin="$build/devel/lib/elo_odometry"
scans="$data/real/hdl64_drive_a"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

run() {  # elo_run over $1 with the other arguments, printing its summary
  local input=$1
  shift
  "$bin/elo_run" --input "$input" --output "$out/poses.txt" --quiet "$@" | sed -n '/^stage/,$p'
}

if [ -d "$scans" ]; then
  for mode in f2m f2f; do
    for threads in 1 2; do
      echo "=== CPU, $mode, $threads thread(s), $(basename "$scans") ($(ls "$scans" | wc -l) scans)"
      run "$scans" --mode "$mode" --threads "$threads"
    done
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
