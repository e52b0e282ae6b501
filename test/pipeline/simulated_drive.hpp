// Shared by the accuracy gates on simulated drives: one odometry per config over the same simulated
// scans, each trajectory evaluated against the exact ground truth.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "elo/eval/evaluation.hpp"
#include "elo/pipeline/odometry.hpp"
#include "elo/sim/simulation.hpp"

namespace elo::test {

// Runs one odometry per config over the simulated drive, every scan through all of them, and evaluates
// each trajectory against the truth at the scans' reference instants, over segments of `segment_lengths`
// starting every `start_step` scans.
inline std::vector<TrajectoryEvaluation> evaluateOnDrive(
    const sim::SimulationSpec& spec, const std::vector<Config>& configs,
    const std::vector<double>& segment_lengths = kittiSegmentLengths(), size_t start_step = kKittiStartFrameStep) {
  const sim::Simulation simulation(spec);
  std::vector<std::unique_ptr<Odometry>> runs;
  for (const Config& config : configs) runs.push_back(std::make_unique<Odometry>(config));
  std::vector<Eigen::Isometry3d> truth;
  std::vector<std::vector<Eigen::Isometry3d>> estimates(configs.size());
  const Eigen::Isometry3d start = simulation.sensorPose(0);
  for (int frame = 0; frame < simulation.frameCount(); ++frame) {
    const PointCloud cloud = simulation.scan(frame).cloud;
    truth.push_back(start.inverse() * simulation.sensorPose(frame));
    for (size_t i = 0; i < runs.size(); ++i) {
      const FrameResult result = runs[i]->process(cloud);
      EXPECT_TRUE(result.processed) << "run " << i << ", frame " << frame << ": " << result.skip_reason;
      estimates[i].push_back(result.pose);
    }
  }
  std::vector<TrajectoryEvaluation> evaluations;
  const std::string name = sim::worldName(spec.world) + "/" + sim::trajectoryName(spec.trajectory);
  for (const auto& estimate : estimates) {
    evaluations.push_back(evaluateTrajectory(name, truth, estimate, segment_lengths, start_step));
  }
  return evaluations;
}

}  // namespace elo::test
