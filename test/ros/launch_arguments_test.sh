#!/usr/bin/env bash
# Every argument of the launch files is documented, and roslaunch --ros-args lists as required only
# those a user must give (it lists any argument with an empty default as required); rviz is off unless
# asked for (make deps does not install it). Run in the catkin
# environment (devel/env.sh), which makes the package known to roslaunch. Usage:
#   launch_arguments_test.sh LAUNCH_DIR
set -euo pipefail
launch_dir=$1
declare -A required=([elo.launch]="" [elo_node.launch]="" [elo_bag.launch]="bag trajectory_file" [elo_localization.launch]="map")
status=0
for file in "$launch_dir"/*.launch; do
  name=$(basename "$file")
  [ -n "${required[$name]+listed}" ] || { echo "FAIL $name: not listed in this test"; status=1; continue; }
  listing=$(roslaunch "$file" --ros-args)
  if grep -q undocumented <<<"$listing"; then
    echo "FAIL $name: undocumented arguments:"; grep undocumented <<<"$listing"; status=1
  fi
  if ! grep -q '^  rviz (default "false")' <<<"$listing"; then
    echo "FAIL $name: rviz must default to false"; status=1
  fi
  listed=$(sed -n '/^Required Arguments:/,/^Optional Arguments:/{s/^  \([^:]*\):.*/\1/p}' <<<"$listing" | xargs)
  if [ "$listed" != "${required[$name]}" ]; then
    echo "FAIL $name: required arguments '$listed', expected '${required[$name]}'"; status=1
  fi
done
# The included parameter file is not listed by --ros-args: its arguments need their doc too.
if grep '<arg ' "$launch_dir"/*.xml | grep -v 'doc='; then
  echo "FAIL: arguments without doc= above"; status=1
fi
[ "$status" = 0 ] && echo "every launch argument documented, rviz off; required: only elo_bag.launch's ${required[elo_bag.launch]} and elo_localization.launch's ${required[elo_localization.launch]}"
exit "$status"
