#!/usr/bin/env bash
# Speed figures of the offline runner: frame-to-model and frame-to-frame on the 60 real HDL-64E scans
# with 1 and 2 threads (per-stage ms as the paper's Table V, FPS, peak memory). Usage:
#   tools/bench.sh BUILD_DIR SHARED_DATA_DIR
set -euo pipefail
build=${1:-build}
data=${2:-../shared/data}
bin="$build/devel/lib/elo_odometry"
scans="$data/real/hdl64_drive_a"
if [ ! -d "$scans" ]; then
  echo "bench: no real scans at $scans (shared data absent); nothing to measure" >&2
  exit 0
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for mode in f2m f2f; do
  for threads in 1 2; do
    echo "=== $mode, $threads thread(s), $(basename "$scans") ($(ls "$scans" | wc -l) scans)"
    "$bin/elo_run" --input "$scans" --output "$out/poses.txt" --mode "$mode" --threads "$threads" --quiet |
      sed -n '/^stage/,$p'
  done
done
