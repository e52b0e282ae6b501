#!/usr/bin/env bash
# Writes a build's elo_run poses on the shared real scans into OUT_DIR, one file per setting: f2m.txt
# (frame-to-model), f2f.txt (frame-to-frame) and f2m_azimuth.txt (frame-to-model with azimuth times);
# the pose files print each double exactly. tools/same_poses.sh compares two such directories: the
# baseline x86-64 build's or Debian 11's against the -march=native build's (docs/platforms.md). Without
# the scans it writes nothing and says so.
# usage: tools/poses_of.sh BUILD SCANS OUT_DIR
set -euo pipefail
[ $# -eq 3 ] || { echo "usage: $0 BUILD SCANS OUT_DIR" >&2; exit 2; }
build=$1 scans=$2 out=$3
bin=$build/devel/lib/elo_odometry/elo_run  # catkin puts the tools under devel/
[ -x "$bin" ] || bin=$build/tools/elo_run
[ -x "$bin" ] || { echo "poses_of: no elo_run in $build" >&2; exit 2; }
rm -rf "$out"
mkdir -p "$out"
if [ ! -d "$scans" ]; then
  echo "poses_of: SKIPPED: no real scans at $scans (the shared data, ../shared/data)"
  exit 0
fi
while read -r name setting; do
  # shellcheck disable=SC2086  # the setting is a list of words
  "$bin" --input "$scans" --output "$out/$name.txt" --quiet $setting </dev/null >/dev/null
done <<'SETTINGS'
f2m --mode f2m
f2f --mode f2f
f2m_azimuth --mode f2m --set deskew.time_source=azimuth
SETTINGS
echo "poses_of: $(ls "$out" | wc -l) settings' poses of $bin in $out"
