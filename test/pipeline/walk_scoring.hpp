// What the walk tests (test_lost_track.cpp, test_imu_walks.cpp) share beyond the walks themselves: how a
// walk is scored, and the platform files it runs under. Apart from simulated_walks.hpp, which the ROS
// tests' fixtures build without the source tree's path.
#pragma once

#include <string>
#include <vector>

#include "elo/config.hpp"
#include "elo/eval/kitti_metric.hpp"
#include "elo/io/config_yaml.hpp"

namespace elo::test {

// The walks' score: the drift of `estimate` against `truth` over 10 m segments, one from every scan.
inline DriftError driftOver10m(const std::vector<Eigen::Isometry3d>& truth,
                               const std::vector<Eigen::Isometry3d>& estimate) {
  return averageDrift(kittiSegmentErrors(truth, estimate, {10.0}, 1));
}

// config/platforms/<platform>.yaml (handheld, legged) on top of `config`, as --config takes it.
inline void loadPlatform(const std::string& platform, Config& config) {
  loadConfigYaml(std::string(ELO_SOURCE_DIR) + "/config/platforms/" + platform + ".yaml", config);
}

}  // namespace elo::test
