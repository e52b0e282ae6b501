#!/usr/bin/env bash
# The built-in demo, needing no downloaded data: simulates about 1 km of urban driving with an
# HDL-64E (exact ground truth), runs the odometry over it, scores it against the ground truth and
# plots it. Usage:
#   tools/demo.sh BUILD_DIR [SHARED_DATA_DIR]
# Writes BUILD_DIR/demo/: sequence/ (KITTI layout), poses.txt (elo_run), timing.csv, trajectory.png,
# sequence.bag and poses_ros.txt (the same drive through the nodelet, replayed from the bag).
set -euo pipefail
build=${1:-build}
bin="$build/devel/lib/elo_odometry"
configs="$(dirname "$0")/../config"
out="$build/demo"
for tool in elo_sim elo_run elo_eval; do
  [ -x "$bin/$tool" ] || { echo "demo: $bin/$tool is missing; build first (make build)" >&2; exit 1; }
done
# 1050 frames at 10 Hz: the drive starts from rest and cruises at 10 m/s, about 1 km in all.
frames=1050
rm -rf "$out"
mkdir -p "$out"

echo "== simulating $frames HDL-64E scans of an urban drive (seed 1)"
"$bin/elo_sim" --world urban --trajectory curves --frames "$frames" --seed 1 --sensor hdl64 \
  --output "$out/sequence"

echo "== running the odometry (frame-to-model)"
"$bin/elo_run" --input "$out/sequence" --output "$out/poses.txt" --config "$configs/hdl64.yaml" \
  --timing "$out/timing.csv" --quiet |
  sed -n '/^stage/,$p'

echo "== scoring against the ground truth"
"$bin/elo_eval" --gt "$out/sequence/poses.txt" --est "$out/poses.txt" --plot "$out/trajectory.png"
echo "plot: $out/trajectory.png"

echo "== replaying the same drive through the ROS nodelet from a bag (headless)"
"$bin/kitti_to_bag" --input "$out/sequence" --output "$out/sequence.bag" --poses-frame lidar >/dev/null
set +u  # catkin's generated setup scripts read unset variables
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
set -u
roslaunch elo_odometry elo_bag.launch bag:="$out/sequence.bag" trajectory_file:="$out/poses_ros.txt" \
  >"$out/roslaunch.log" 2>&1
"$bin/elo_eval" --gt "$out/sequence/poses.txt" --est "$out/poses_ros.txt"
echo "nodelet log: $out/roslaunch.log"
