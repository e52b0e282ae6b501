#!/usr/bin/env bash
# The built-in demo, needing no downloaded data: simulates about 1 km of urban driving with an
# HDL-64E (exact ground truth), runs the odometry over it with elo_run, scores it against the ground
# truth and plots it; then replays the same drive from a bag through the ROS node (elo_bag.launch,
# headless, on a ROS master of its own) and checks that the node wrote elo_run's poses. Usage:
#   tools/demo.sh BUILD_DIR [SHARED_DATA_DIR]
# Environment: DEMO_FRAMES (scans to simulate, default 1050: the whole drive; 60 make a short run),
# DEMO_OUTPUT (default BUILD_DIR/demo), DEMO_KEEP=1 (keep the scans and the bag, which are otherwise
# removed at the end: together 3.6 GB for the whole drive).
# Writes DEMO_OUTPUT/: poses.txt (elo_run), timing.csv, trajectory.png, poses_ros.txt (the node),
# roslaunch.log, sequence/ (times, ground truth, calibration; the scans with DEMO_KEEP=1).
# Exits non-zero, naming the step and its log, when any step fails.
set -euo pipefail
build=${1:-build}
frames=${DEMO_FRAMES:-1050}
bin="$build/devel/lib/elo_odometry"
configs="$(cd "$(dirname "$0")/../config" && pwd)"
for tool in elo_sim elo_run elo_eval kitti_to_bag; do
  [ -x "$bin/$tool" ] || { echo "demo: $bin/$tool is missing; build first (make build)" >&2; exit 1; }
done
[[ "$frames" =~ ^[1-9][0-9]*$ ]] || { echo "demo: DEMO_FRAMES must be a positive integer, got '$frames'" >&2; exit 2; }
out=${DEMO_OUTPUT:-$build/demo}
# Replaces an earlier demo's output, and nothing else.
if [ -n "$(ls -A "$out" 2>/dev/null)" ] && [ ! -e "$out/elo_sim.log" ] && [ ! -e "$out/poses.txt" ]; then
  echo "demo: $out holds files that are not a demo's; name another DEMO_OUTPUT" >&2
  exit 2
fi
rm -rf "$out"
mkdir -p "$out"
# Absolute paths from here on: roslaunch runs its nodes in ROS_HOME, not here.
out=$(cd "$out" && pwd)
bin=$(cd "$bin" && pwd)
build=$(cd "$build" && pwd)

fail() {
  echo "demo: $*" >&2
  exit 1
}
# The scans and the bag are large and made again by the next run.
clean_up() {
  [ "${DEMO_KEEP:-0}" = 1 ] && return
  rm -rf "$out/sequence/velodyne" "$out/sequence.bag"
}
trap clean_up EXIT
current_step=""
trap 'echo "demo: failed while $current_step" >&2' ERR
step() {
  current_step=$*
  echo "== $* (at $SECONDS s)"
}

step "simulating $frames HDL-64E scans of an urban drive (seed 1)"
# The drive starts from rest and cruises at 10 m/s: 1050 frames at 10 Hz are about 1 km.
"$bin/elo_sim" --world urban --trajectory curves --frames "$frames" --seed 1 --sensor hdl64 \
  --output "$out/sequence" >"$out/elo_sim.log" 2>&1 || fail "elo_sim failed; see $out/elo_sim.log"

step "running the odometry (elo_run, frame-to-model)"
"$bin/elo_run" --input "$out/sequence" --output "$out/poses.txt" --config "$configs/hdl64.yaml" \
  --timing "$out/timing.csv" --quiet >"$out/elo_run.log" 2>&1 || fail "elo_run failed; see $out/elo_run.log"
sed -n '/^frames/,$p' "$out/elo_run.log"

step "scoring against the ground truth"
"$bin/elo_eval" --gt "$out/sequence/poses.txt" --est "$out/poses.txt" --plot "$out/trajectory.png"
echo "plot: $out/trajectory.png"

step "replaying the drive through the ROS node from a bag (headless)"
"$bin/kitti_to_bag" --input "$out/sequence" --output "$out/sequence.bag" --poses-frame lidar >/dev/null
# shellcheck source=tools/private_ros_master.sh
source "$(dirname "$0")/private_ros_master.sh"
private_ros_master "$build" "$out"
# Played as fast as elo_run went (up to twice real time), with a margin: the node processes every scan,
# and what it has not finished 15 s after the bag ends is lost when roslaunch stops it.
scan_rate=10
rate=$(sed -n 's/^FPS: .*, \([0-9.]*\) (wall.*/\1/p' "$out/elo_run.log" |
  awk -v hz="$scan_rate" '{ r = 0.7 * $1 / hz; if (r > 2) r = 2; if (r < 0.1) r = 0.1; printf "%.2f", r }')
echo "bag played at ${rate}x (master on port $port)"
log="$out/roslaunch.log"
roslaunch -p "$port" elo_odometry elo_bag.launch bag:="$out/sequence.bag" trajectory_file:="$out/poses_ros.txt" \
  rate:="$rate" >"$log" 2>&1 || fail "roslaunch failed; see $log"
# roslaunch exits 0 when a required node dies, so the log and the trajectory decide.
if grep -q 'process has died' "$log"; then
  grep 'process has died' "$log" >&2
  fail "a node died during the replay; see $log"
fi
[ -f "$out/poses_ros.txt" ] || fail "the node wrote no trajectory; see $log"
ros_poses=$(wc -l <"$out/poses_ros.txt")
[ "$ros_poses" -eq "$frames" ] ||
  fail "the node wrote $ros_poses poses for $frames scans (it could not keep up, or scans were dropped); see $log"
"$bin/elo_eval" --gt "$out/sequence/poses.txt" --est "$out/poses_ros.txt"
largest=$(paste -d ' ' "$out/poses.txt" "$out/poses_ros.txt" | awk '{
  d = 0; for (i = 1; i <= 12; i++) { e = $i - $(i + 12); if (e < 0) e = -e; if (e > d) d = e }
  if (d > largest) largest = d } END { printf "%.3g", largest }')
# The node counts time as elo_run does (nanoseconds since the first scan): its poses are elo_run's.
[ "$largest" = 0 ] || fail "the node's poses differ from elo_run's by up to $largest (a pose matrix entry); see $log"
echo "the node's poses are elo_run's, bit for bit"
echo "nodelet log: $log"

clean_up
echo "== done in $SECONDS s; $out holds $(du -sh "$out" | cut -f1)"
