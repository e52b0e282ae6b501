# Sourced by tools/demo.sh and tools/soak.sh. private_ros_master BUILD OUT: the package's catkin
# environment from BUILD, and a ROS master of our own on a free port ($port, for roslaunch -p) with ROS's
# files under OUT/ros_home: nothing shared with other ROS users.
private_ros_master() {
  set +u  # catkin's generated setup scripts read unset variables
  # shellcheck disable=SC1091
  source "$1/devel/setup.bash"
  set -u
  port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')
  export ROS_MASTER_URI="http://localhost:$port"
  export ROS_HOME="$2/ros_home"
  export ROS_LOG_DIR="$2/ros_home/log"
  mkdir -p "$ROS_LOG_DIR"
}
