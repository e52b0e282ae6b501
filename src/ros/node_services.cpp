#include "node_services.hpp"

#include <functional>
#include <stdexcept>

#include "elo/io/kitti.hpp"
#include "elo/io/map_pcd.hpp"
#include "elo/io/pcd.hpp"

namespace elo_ros {
namespace {

// A service's answer: what `save` returned, or why it failed.
bool answer(std_srvs::Trigger::Response& response, const std::function<std::string()>& save) {
  try {
    response.message = save();
    response.success = true;
  } catch (const std::exception& error) {
    response.message = error.what();
    response.success = false;
  }
  return true;
}

}  // namespace

NodeServices::NodeServices(ros::NodeHandle& private_node, std::string name, const NodeSettings& settings,
                           elo::DriveSession& session, const std::optional<FrameBinding>& frames)
    : private_node_(private_node), name_(std::move(name)), settings_(settings), session_(session), frames_(frames) {
  reset_service_ = private_node.advertiseService("reset", &NodeServices::onReset, this);
  save_trajectory_service_ = private_node.advertiseService("save_trajectory", &NodeServices::onSaveTrajectory, this);
  save_map_service_ = private_node.advertiseService("save_map", &NodeServices::onSaveMap, this);
  save_model_service_ = private_node.advertiseService("save_model", &NodeServices::onSaveModel, this);
}

bool NodeServices::onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  session_.reset();
  response.success = true;
  response.message = "odometry reset: the next scan starts a new trajectory at the origin";
  ROS_INFO_NAMED(name_, "%s", response.message.c_str());
  return true;
}

std::string NodeServices::saveTrajectory(const OutputFiles& files) {
  if (files.trajectory_file.empty()) throw std::invalid_argument("~trajectory_file is not set");
  const TrajectoryFormat format = parseTrajectoryFormat(files.trajectory_format);
  // The sensor's poses since the odometry last started, as elo_run writes them.
  const elo::DriveTrajectory trajectory = session_.trajectory();
  if (format == TrajectoryFormat::kitti) {
    elo::writeKittiPoses(files.trajectory_file, trajectory.odometry);
  } else {
    elo::writeTumPoses(files.trajectory_file, trajectory.stamps, trajectory.odometry);
  }
  return "wrote " + std::to_string(trajectory.odometry.size()) + " sensor poses (" + files.trajectory_format +
         ") to " + files.trajectory_file;
}

void NodeServices::saveTrajectoryOnShutdown() {
  try {
    ROS_INFO_NAMED(name_, "%s", saveTrajectory(settings_.outputs).c_str());
  } catch (const std::exception& error) {
    ROS_ERROR_NAMED(name_, "cannot save the trajectory on shutdown: %s", error.what());
  }
}

bool NodeServices::onSaveTrajectory(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  return answer(response, [&] { return saveTrajectory(readOutputFiles(private_node_)); });
}

std::string NodeServices::saveMap(const OutputFiles& files) {
  if (files.map_file.empty()) throw std::invalid_argument("~map_file is not set");
  elo::MapBuilder* map = session_.driveMap();
  if (!map) throw std::runtime_error("~build_map is false: no map was built");
  // Every scan processed so far is in the map once it returns.
  const elo::MapCloud cloud = map->points();
  elo::writeMapPcd(files.map_file, cloud);
  const elo::MapBuilder::Statistics statistics = map->statistics();
  return "wrote the drive's map, " + std::to_string(cloud.size()) + " points from " + std::to_string(statistics.scans) +
         " scans (" + settings_.odom_frame + " frame), to " + files.map_file;
}

bool NodeServices::onSaveMap(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  return answer(response, [&] { return saveMap(readOutputFiles(private_node_)); });
}

std::string NodeServices::saveModel(const OutputFiles& files) {
  if (files.model_file.empty()) throw std::invalid_argument("~model_file is not set");
  elo::PointCloud model;
  session_.withOdometry([&](elo::Odometry& odometry, bool processed) {
    if (!frames_ || !processed) throw std::runtime_error("no scan processed yet: the model is empty");
    // The model lives in the latest scan's frame at its reference instant (mid-sweep for per-point times
    // from the cloud: Odometry::modelPose()); the file holds it in the odom frame.
    model = modelPoints(odometry.backend().model(), frames_->sensorPose(odometry.modelPose()));
  });
  elo::writePcd(files.model_file, model);
  return "wrote " + std::to_string(model.size()) + " model points (" + settings_.odom_frame + " frame) to " +
         files.model_file;
}

bool NodeServices::onSaveModel(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  return answer(response, [&] { return saveModel(readOutputFiles(private_node_)); });
}

}  // namespace elo_ros
