#!/usr/bin/env bash
# Replays a bag through elo_bag.launch with rviz:=true on a virtual screen (Xvfb, no display needed)
# and saves what rviz shows once the bag has ended and the odometry has caught up. Usage:
#   tools/rviz_screenshot.sh BUILD_DIR OUTPUT.png [BAG] [RVIZ_CONFIG]
# Without BAG (or with an empty one) it simulates a 20 s urban drive (elo_sim --bag) and replays that.
# RVIZ_CONFIG defaults to rviz/elo.rviz (rviz/elo_map.rviz: the drive's map from above). Needs xvfb and netpbm
# (make rviz-screenshot installs them). ELO_SCREENSHOT_WIDTH scales the picture (default 1200 pixels).
set -euo pipefail
build=${1:?usage: tools/rviz_screenshot.sh BUILD_DIR OUTPUT.png [BAG]}
output=${2:?usage: tools/rviz_screenshot.sh BUILD_DIR OUTPUT.png [BAG]}
bag=${3:-}
rviz_config=$(realpath "${4:-$(dirname "$0")/../rviz/elo.rviz}")
width=${ELO_SCREENSHOT_WIDTH:-1200}
bin="$build/devel/lib/elo_odometry"
for tool in Xvfb xwdtopnm pnmtopng rviz; do
  command -v "$tool" >/dev/null || { echo "rviz_screenshot: $tool is missing (make rviz-screenshot installs it)" >&2; exit 1; }
done

work=$(mktemp -d)
pids=()
cleanup() {
  # SIGTERM: a background job of a script ignores SIGINT. roslaunch takes its nodes down; Xvfb goes
  # last, once rviz has let go of it.
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do
    kill -TERM "${pids[i]}" 2>/dev/null || true
    wait "${pids[i]}" 2>/dev/null || true
  done
  rm -rf "$work"
}
trap cleanup EXIT

if [ -z "$bag" ]; then
  echo "== simulating a 20 s urban drive"
  "$bin/elo_sim" --world urban --trajectory curves --frames 200 --seed 1 --output "$work/sequence" \
    --bag "$work/sequence.bag" >/dev/null
  bag="$work/sequence.bag"
fi
bag=$(realpath "$bag")  # roslaunch runs the player in ~/.ros

# A screen of rviz's window size (rviz/elo.rviz); Xvfb picks a free display number and writes its frame
# buffer as an XWD file into $work.
Xvfb -displayfd 3 -screen 0 1400x900x24 -fbdir "$work" -nolisten tcp -nocursor 3>"$work/display" 2>"$work/xvfb.log" &
pids+=($!)
for _ in $(seq 50); do [ -s "$work/display" ] && break; sleep 0.1; done
[ -s "$work/display" ] || { echo "rviz_screenshot: Xvfb did not start:" >&2; cat "$work/xvfb.log" >&2; exit 1; }
DISPLAY=":$(cat "$work/display")"
export DISPLAY

# A master of our own on a free port, so that other ROS graphs on this machine are left alone.
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://localhost:$port"
set +u  # catkin's generated setup scripts read unset variables
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
set -u
echo "== replaying $bag into rviz on $DISPLAY (master port $port)"
roslaunch -p "$port" elo_odometry elo_bag.launch bag:="$bag" trajectory_file:="$work/poses.txt" rviz:=true \
  rviz_config:="$rviz_config" \
  >"$work/roslaunch.log" 2>&1 &
pids+=($!)

# The odometry has caught up when it publishes the pose of the bag's last scan (the waiter subscribes
# before the player starts, so it sees every pose); then rviz gets a moment to draw it.
# Debian's python3, which has rospy, whatever python3 comes first on PATH.
/usr/bin/python3 - "$bag" <<'EOF_PY' &
import struct
import sys
import threading
import rosbag
import rospy

last_scan = rosbag.Bag(sys.argv[1]).get_end_time()
caught_up = threading.Event()


def on_odometry(message):
    # A stamped message starts with its header: seq, then the stamp's secs and nsecs (little-endian).
    # Read raw, so that no message package beyond rospy's own is needed.
    secs, nsecs = struct.unpack_from("<II", message._buff, 4)
    if secs + nsecs * 1e-9 >= last_scan - 0.05:
        caught_up.set()


rospy.init_node("rviz_screenshot_wait", anonymous=True, disable_signals=True)
rospy.Subscriber("/elo/odom", rospy.AnyMsg, on_odometry)
if not caught_up.wait(timeout=900):  # wall seconds
    sys.exit("rviz_screenshot: the odometry did not reach the bag's last scan within 15 minutes")
EOF_PY
waiter=$!
while kill -0 "$waiter" 2>/dev/null; do
  if ! kill -0 "${pids[1]}" 2>/dev/null || grep -q 'player-[0-9]*\] process has died' "$work/roslaunch.log"; then
    echo "rviz_screenshot: the replay failed:" >&2; cat "$work/roslaunch.log" >&2; kill "$waiter"; exit 1
  fi
  sleep 1
done
wait "$waiter"
sleep 3

mkdir -p "$(dirname "$output")"
xwdtopnm "$work/Xvfb_screen0" 2>/dev/null | pamscale -width "$width" | pnmquant 128 2>/dev/null | pnmtopng -compression 9 >"$output"
echo "screenshot: $output ($(du -k "$output" | cut -f1) KB)"
