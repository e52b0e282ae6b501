// elo_odometry_node: the odometry nodelet as a process of its own, for setups without a nodelet manager.
#include <ros/ros.h>

#include <exception>

#include "odometry_nodelet.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "elo_odometry");
  elo_ros::OdometryNodelet odometry;
  try {
    // No remappings of its own and no queues: the node's remappings and global queue serve the nodelet.
    odometry.init(ros::this_node::getName(), {}, std::vector<std::string>(argv + 1, argv + argc));
  } catch (const std::exception&) {
    return 1;  // onInit has logged why
  }
  ros::spin();
  return 0;
}
