// ROS parameters <-> the core's configuration, and the node's own settings. The core's parameters are
// set only through elo::parameters(), the one table of keys and defaults: a private parameter
// `~ground/max_slope_deg` is the table's `ground.max_slope_deg`, so YAML files loaded with rosparam and
// elo_run's --config files are the same files.
#pragma once

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <string>
#include <utility>
#include <vector>

#include "elo/config.hpp"

namespace elo_ros {

// Sets every core parameter that `tree` (the node's private namespace as the parameter server returns
// it) holds, then the shortcuts `backend` (runtime.backend), `threads` (runtime.threads) and `mode`
// (model.mode: f2m, f2f or the full choice name), which win over the nested keys. Throws
// elo::ConfigError naming the parameter for a value of the wrong type or an unknown choice. Returns the
// parameters under a config section (`~ground/...`) that name no core parameter, such as a misspelling.
std::vector<std::string> applyConfigParameters(XmlRpc::XmlRpcValue tree, elo::Config& config);

// Every core parameter as (private name relative to the node, value): `ground/max_slope_deg`. The node
// sets them back on the parameter server, which then shows the configuration the node runs with.
std::vector<std::pair<std::string, XmlRpc::XmlRpcValue>> effectiveParameters(elo::Config& config);

// The core's configuration from the private namespace (applyConfigParameters(); the parameters that
// name no core parameter are warned of under `logger`), validated (throws elo::ConfigError), then set
// back on the parameter server (effectiveParameters()).
elo::Config readConfig(ros::NodeHandle& private_node, const std::string& logger);

enum class TrajectoryFormat { kitti, tum };

// Where and how the services write. The services re-read them at each call, so that `rosparam set`
// can point them elsewhere; writing on shutdown uses the values the node started with.
struct OutputFiles {
  std::string trajectory_file;
  std::string trajectory_format = "kitti";  // kitti | tum
  std::string map_file;    // ~save_map: the drive's map (docs/map.md)
  std::string model_file;  // ~save_model: the model, the last model.time_window seconds
};

// The node's own settings; the defaults are here and nowhere else.
struct NodeSettings {
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  // Publish odom -> <the cloud's frame> instead of odom -> base_frame: for a sensor with no base_link.
  bool publish_sensor_frame_directly = false;
  bool publish_tf = true;  // false when another node (a filter) owns odom -> base_link
  // Queue every scan (bag replay: none may be lost) instead of processing only the latest one (on a
  // vehicle: a late pose is worth less than a fresh one; the scans replaced are counted as dropped).
  bool process_every_scan = false;
  int path_length = 1000;           // poses `path` keeps, the oldest dropped first; 0: no limit
  double model_publish_rate = 1.0;  // Hz of scan time for model/*; 0: never
  bool build_map = true;            // the drive's map, for ~save_map and `map` (docs/map.md)
  double map_publish_period = 5.0;  // s of scan time between `map` messages; 0: never
  int map_publish_points = 500000;  // at most this many voxels in a `map` message (thinned evenly)
  double tf_timeout = 1.0;          // s to wait for the sensor -> base extrinsic on a scan
  // With imu.enabled: the IMU's mount from TF (the Imu messages' frame in the clouds' frame) instead of
  // imu.position and imu.rotation_deg; and how long (s, wall) a scan waits for the IMU samples over its sweep.
  bool imu_mount_from_tf = false;
  double imu_max_wait = 0.05;
  OutputFiles outputs;
  bool save_trajectory_on_shutdown = false;  // write the trajectory file when the node stops (bag replay)
};

// Reads the settings from the private namespace. Throws std::invalid_argument naming a parameter whose
// value cannot work or has the wrong type.
NodeSettings readNodeSettings(const ros::NodeHandle& private_node);

OutputFiles readOutputFiles(const ros::NodeHandle& private_node);

// Parses `kitti` or `tum`; throws std::invalid_argument otherwise.
TrajectoryFormat parseTrajectoryFormat(const std::string& text);

}  // namespace elo_ros
