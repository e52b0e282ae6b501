#!/usr/bin/env bash
# The soak test: hours of driving through the ROS nodelet at the sensor's own rate, without a bag of
# that size on disk. Simulates one lap of a closed urban circuit once (400 HDL-64E scans, 40 s), starts
# the nodelet in a manager (launch/elo.launch, every scan processed), and has tools/sequence_player
# publish the lap over and over with stamps running on, while tools/soak_monitor samples the manager's
# resident memory and the nodelet's diagnostics. Usage:
#   tools/soak.sh BUILD_DIR [SCANS] [RATE]
# SCANS defaults to 20000 (33 min at 10 Hz), RATE (playback speed) to 1. Environment: SOAK_BLOCK (scans
# per table row, default 1000), SOAK_WARMUP (scans before the memory baseline, default 1000),
# SOAK_RSS_TOLERANCE (MiB of growth allowed after warm-up, default 16), SOAK_BACKLOG (scans allowed to
# wait for the nodelet after warm-up, default 10), SOAK_THREADS (odometry threads, default 2), SOAK_INPUT
# (a sequence directory to play instead of the simulated lap, e.g. the real scans, to time the ROS layer). The
# nodelet must keep up with RATE: on a loaded machine, lower it. Writes BUILD_DIR/soak/: sequence/ (kept
# for the next run), roslaunch.log, player.log, report.txt. Exits with the monitor's status: 0 when the
# memory stayed flat, the nodelet kept up and every scan is accounted for.
set -euo pipefail
build=${1:-build}
scans=${2:-20000}
rate=${3:-1}
block=${SOAK_BLOCK:-1000}
warmup=${SOAK_WARMUP:-1000}
tolerance=${SOAK_RSS_TOLERANCE:-16}
backlog=${SOAK_BACKLOG:-10}
threads=${SOAK_THREADS:-2}
bin="$build/devel/lib/elo_odometry"
for tool in elo_sim sequence_player soak_monitor; do
  [ -x "$bin/$tool" ] || { echo "soak: $bin/$tool is missing; build first (make build)" >&2; exit 1; }
done
mkdir -p "$build/soak"
out=$(cd "$build/soak" && pwd)  # absolute: the ROS processes run elsewhere

# One lap of the urban loop is 40 s (400 scans at 10 Hz): played end to end, it is one continuous drive.
lap_frames=400
sim_args="--world urban --trajectory loop --frames $lap_frames --seed 1 --sensor hdl64"
sequence="${SOAK_INPUT:-$out/sequence}"
if [ -n "${SOAK_INPUT:-}" ]; then
  [ -d "$SOAK_INPUT" ] || { echo "soak: SOAK_INPUT=$SOAK_INPUT is not a directory" >&2; exit 1; }
  sequence=$(cd "$SOAK_INPUT" && pwd)
elif [ "$(cat "$out/sequence/.elo_sim_args" 2>/dev/null)" != "$sim_args" ]; then
  echo "== simulating one lap of the urban loop ($lap_frames HDL-64E scans)"
  rm -rf "$out/sequence"
  # shellcheck disable=SC2086
  "$bin/elo_sim" $sim_args --output "$out/sequence"
  echo "$sim_args" >"$out/sequence/.elo_sim_args"
fi

# shellcheck source=tools/private_ros_master.sh
source "$(dirname "$0")/private_ros_master.sh"
private_ros_master "$build" "$out"

launch_pid=""
monitor_pid=""
stop() {
  [ -n "$monitor_pid" ] && kill -INT "$monitor_pid" 2>/dev/null || true
  [ -n "$launch_pid" ] && kill -INT "$launch_pid" 2>/dev/null && wait "$launch_pid" 2>/dev/null || true
}
trap stop EXIT

echo "== starting the nodelet in a manager (master on port $port)"
roslaunch -p "$port" elo_odometry elo.launch cloud_topic:=/points sensor:=hdl64 threads:="$threads" \
  process_every_scan:=true publish_sensor_frame_directly:=true rviz:=false >"$out/roslaunch.log" 2>&1 &
launch_pid=$!
until (: </dev/tcp/localhost/"$port") 2>/dev/null; do  # the master listens
  kill -0 "$launch_pid" 2>/dev/null || { echo "soak: roslaunch failed, see $out/roslaunch.log" >&2; exit 1; }
  sleep 0.5
done

echo "== playing $scans scans at ${rate}x; report every $block scans"
# The monitor waits for the manager to register; the player for the nodelet and the monitor to listen.
"$bin/soak_monitor" --scans "$scans" --manager /elo/elo_manager --points /points --odom /elo/odom \
  --block "$block" --warmup "$warmup" --rss-tolerance "$tolerance" --backlog "$backlog" >"$out/report.txt" 2>&1 &
monitor_pid=$!
if ! "$bin/sequence_player" --input "$sequence" --topic /points --scans "$scans" --rate "$rate" \
  --subscribers 2 --progress "$block" | tee "$out/player.log"; then
  echo "soak: the player failed; see $out/roslaunch.log and $out/report.txt" >&2
  exit 1
fi
status=0
wait "$monitor_pid" || status=$?
monitor_pid=""
cat "$out/report.txt"
exit "$status"
