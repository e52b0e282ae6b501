// Registers the nodelet with pluginlib. Only the plugin library compiles this file: the standalone node
// links the same class without registering it, so class_loader never sees a plugin it did not load.
#include <pluginlib/class_list_macros.hpp>

#include "odometry_nodelet.hpp"

PLUGINLIB_EXPORT_CLASS(elo_ros::OdometryNodelet, nodelet::Nodelet)
