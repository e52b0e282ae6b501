// The node's services: ~reset, ~save_trajectory, ~save_map and ~save_model, over the drive session.
#pragma once

#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <optional>
#include <string>

#include "elo/drive_session.hpp"
#include "messages.hpp"
#include "parameters.hpp"

namespace elo_ros {

class NodeServices {
 public:
  // `frames`: the node's, set under the session's lock (DriveSession::withOdometry()) once bound.
  NodeServices(ros::NodeHandle& private_node, std::string name, const NodeSettings& settings,
               elo::DriveSession& session, const std::optional<FrameBinding>& frames);

  // Writes the trajectory to `files`; returns what it wrote; throws on failure.
  std::string saveTrajectory(const OutputFiles& files);
  // ~save_trajectory_on_shutdown: to the files the node started with, saying what it wrote or why it could not.
  void saveTrajectoryOnShutdown();

 private:
  bool onReset(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool onSaveTrajectory(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool onSaveMap(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool onSaveModel(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  std::string saveMap(const OutputFiles& files);
  std::string saveModel(const OutputFiles& files);

  ros::NodeHandle& private_node_;
  std::string name_;
  const NodeSettings& settings_;
  elo::DriveSession& session_;
  const std::optional<FrameBinding>& frames_;
  ros::ServiceServer reset_service_, save_trajectory_service_, save_map_service_, save_model_service_;
};

}  // namespace elo_ros
