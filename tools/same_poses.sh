#!/usr/bin/env bash
# The poses of two builds' elo_run on the shared real scans, compared in frame-to-model, frame-to-frame
# and frame-to-model with azimuth times (the pose files print each double exactly). `make test-baseline`
# runs it on the baseline x86-64 build (ELO_NATIVE=OFF: no AVX, no FMA) against the -march=native one
# (docs/platforms.md). Without BOUND the poses must be the same bit for bit; with it, no pose entry may
# differ by more than BOUND (metres for translations). Prints by how much each setting's poses differ;
# skips, saying so, without the scans.
# usage: tools/same_poses.sh BUILD_A BUILD_B SCANS [BOUND]
set -euo pipefail
[ $# -eq 3 ] || [ $# -eq 4 ] || { echo "usage: $0 BUILD_A BUILD_B SCANS [BOUND]" >&2; exit 2; }
scans=$3
bound=${4:-0}
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

compare() {  # SETTING: prints how many poses differ and by how much; fails past the bound
  python3 - "$out/a.txt" "$out/b.txt" "$bound" "$1" <<'PY'
import sys
a = [list(map(float, line.split())) for line in open(sys.argv[1])]
b = [list(map(float, line.split())) for line in open(sys.argv[2])]
bound, setting = float(sys.argv[3]), sys.argv[4]
if len(a) != len(b) or not a:
    sys.exit(f"same_poses: {setting}: {len(a)} against {len(b)} poses")
differing = sum(x != y for x, y in zip(a, b))
largest = max(abs(u - v) for x, y in zip(a, b) for u, v in zip(x, y))
if differing == 0:
    print(f"same_poses: {setting}: the {len(a)} poses are the same bit for bit")
else:
    print(f"same_poses: {setting}: {differing} of {len(a)} poses differ, by up to {largest:.3g} "
          f"in an entry (m for translations; bound {bound:g})")
sys.exit(1 if largest > bound else 0)
PY
}

status=0
for setting in "--mode f2m" "--mode f2f" "--mode f2m --set deskew.time_source=azimuth"; do
  # shellcheck disable=SC2086  # the setting is a list of words
  "$run_a" --input "$scans" --output "$out/a.txt" --quiet $setting >/dev/null
  # shellcheck disable=SC2086
  "$run_b" --input "$scans" --output "$out/b.txt" --quiet $setting >/dev/null
  compare "$setting" || status=1
done
exit $status
