#!/usr/bin/env bash
# The poses of two builds' elo_run on the shared real scans, compared byte for byte (the pose files
# print each double exactly), in frame-to-model, frame-to-frame and frame-to-model with azimuth times.
# `make test-baseline` runs it on the baseline x86-64 build (ELO_NATIVE=OFF: no AVX, no FMA) against
# the -march=native one: the scalar code the AVX lanes stand in for must give the same poses
# (docs/platforms.md). Fails where a setting's poses differ, printing by how much; skips, saying so,
# without the scans.
# usage: tools/same_poses.sh BUILD_A BUILD_B SCANS
set -euo pipefail
[ $# -eq 3 ] || { echo "usage: $0 BUILD_A BUILD_B SCANS" >&2; exit 2; }
scans=$3
if [ ! -d "$scans" ]; then
  echo "same_poses: SKIPPED: no real scans at $scans (the shared data, ../shared/data)"
  exit 0
fi
elo_run_of() {  # catkin puts the tools under devel/
  local bin=$1/devel/lib/elo_odometry/elo_run
  [ -x "$bin" ] || bin=$1/tools/elo_run
  [ -x "$bin" ] || { echo "same_poses: no elo_run in $1" >&2; exit 2; }
  echo "$bin"
}
run_a=$(elo_run_of "$1")
run_b=$(elo_run_of "$2")
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

largest_difference() {  # the largest difference of any pose entry, and how many poses differ
  python3 - "$1" "$2" <<'PY'
import sys
a = [list(map(float, line.split())) for line in open(sys.argv[1])]
b = [list(map(float, line.split())) for line in open(sys.argv[2])]
if len(a) != len(b):
    print(f"{len(a)} against {len(b)} poses")
else:
    differing = sum(x != y for x, y in zip(a, b))
    largest = max(abs(u - v) for x, y in zip(a, b) for u, v in zip(x, y))
    print(f"{differing} of {len(a)} poses differ, by up to {largest:.3g} in an entry (m for translations)")
PY
}

status=0
for setting in "--mode f2m" "--mode f2f" "--mode f2m --set deskew.time_source=azimuth"; do
  # shellcheck disable=SC2086  # the setting is a list of words
  "$run_a" --input "$scans" --output "$out/a.txt" --quiet $setting >/dev/null
  # shellcheck disable=SC2086
  "$run_b" --input "$scans" --output "$out/b.txt" --quiet $setting >/dev/null
  if cmp -s "$out/a.txt" "$out/b.txt"; then
    echo "same_poses: $setting: the $(wc -l <"$out/a.txt") poses are the same bit for bit"
  else
    echo "same_poses: $setting: $(largest_difference "$out/a.txt" "$out/b.txt")" >&2
    status=1
  fi
done
exit $status
