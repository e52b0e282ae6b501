// Accuracy gates on a simulated drive with exact ground truth: a regression that makes drift 20% worse
// than the figure measured when the gate was set must fail.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "elo/eval/evaluation.hpp"
#include "elo/odometry.hpp"
#include "elo/sim/simulation.hpp"

namespace elo {
namespace {

struct Gate {
  RegistrationMode mode;
  double measured_t_rel;  // % on the drive below when the gate was set
  double measured_r_rel;  // deg/100 m
};

// 300 scans (about 270 m) of the urban world on the `curves` drive, HDL-64E, seed 11.
TEST(SimulatedAccuracy, UrbanDriveStaysWithinTwentyPercentOfTheMeasuredDrift) {
  sim::SimulationSpec spec;
  spec.world = sim::WorldFamily::urban;
  spec.trajectory = sim::TrajectoryKind::curves;
  spec.frames = 300;
  spec.seed = 11;
  const sim::Simulation simulation(spec);

  // Measured on 2026-11-22 (266 m): frame-to-model 0.0236 % and 0.0206 deg/100 m, frame-to-frame
  // 0.375 % and 0.271 deg/100 m. The model's same-surface rule (model.same_surface_distance) took
  // frame-to-model from 0.126 % and 0.069 deg/100 m, the figures under the paper's literal closer-wins.
  const std::vector<Gate> gates = {{RegistrationMode::frame_to_model, 0.0236, 0.0206},
                                   {RegistrationMode::frame_to_frame, 0.375, 0.271}};
  std::vector<std::unique_ptr<Odometry>> runs;
  for (const Gate& gate : gates) {
    Config config;
    config.model.mode = gate.mode;
    runs.push_back(std::make_unique<Odometry>(config));
  }
  std::vector<Eigen::Isometry3d> truth;
  std::vector<std::vector<Eigen::Isometry3d>> estimates(gates.size());
  const Eigen::Isometry3d start = simulation.sensorPose(0);
  for (int frame = 0; frame < simulation.frameCount(); ++frame) {
    const PointCloud cloud = simulation.scan(frame).cloud;
    truth.push_back(start.inverse() * simulation.sensorPose(frame));
    for (size_t i = 0; i < gates.size(); ++i) {
      const FrameResult result = runs[i]->process(cloud);
      ASSERT_TRUE(result.processed) << "frame " << frame << ": " << result.skip_reason;
      estimates[i].push_back(result.pose);
    }
  }
  for (size_t i = 0; i < gates.size(); ++i) {
    const TrajectoryEvaluation evaluation = evaluateTrajectory("urban", truth, estimates[i]);
    std::cout << (gates[i].mode == RegistrationMode::frame_to_model ? "frame-to-model" : "frame-to-frame")
              << ": t_rel " << evaluation.drift.t_rel_percent << " %, r_rel " << evaluation.drift.r_rel_deg_per_100m
              << " deg/100m over " << evaluation.length_m << " m" << std::endl;
    EXPECT_LT(evaluation.drift.t_rel_percent, 1.2 * gates[i].measured_t_rel);
    EXPECT_LT(evaluation.drift.r_rel_deg_per_100m, 1.2 * gates[i].measured_r_rel);
  }
}

// The paper's Table III on a 300-scan urban drive, seed 1: range-adaptive normals must drift less than
// plain eigen-decomposition and the cross product. Measured 2026-11-22: 0.0248, 0.0437 and 0.0313 %.
// (Table II is not gated: on this drive the non-ground SRI alone drifts 0.0229 %, below the fused 0.0248.)
TEST(SimulatedAccuracy, RangeAdaptiveNormalsWinTableThree) {
  sim::SimulationSpec spec;
  spec.world = sim::WorldFamily::urban;
  spec.trajectory = sim::TrajectoryKind::curves;
  spec.frames = 300;
  spec.seed = 1;
  const sim::Simulation simulation(spec);

  struct Variant {
    std::string name;
    Config config;
  };
  std::vector<Variant> variants(3);
  variants[0].name = "range-adaptive normals";
  variants[1].name = "plain eigen normals";
  variants[1].config.normals.method = NormalMethod::eigen;
  variants[2].name = "cross-product normals";
  variants[2].config.normals.method = NormalMethod::cross_product;
  std::vector<std::unique_ptr<Odometry>> runs;
  for (const Variant& variant : variants) runs.push_back(std::make_unique<Odometry>(variant.config));

  std::vector<Eigen::Isometry3d> truth;
  std::vector<std::vector<Eigen::Isometry3d>> estimates(variants.size());
  const Eigen::Isometry3d start = simulation.sensorPose(0);
  for (int frame = 0; frame < simulation.frameCount(); ++frame) {
    const PointCloud cloud = simulation.scan(frame).cloud;
    truth.push_back(start.inverse() * simulation.sensorPose(frame));
    for (size_t i = 0; i < variants.size(); ++i) estimates[i].push_back(runs[i]->process(cloud).pose);
  }
  std::vector<double> drift;
  for (size_t i = 0; i < variants.size(); ++i) {
    drift.push_back(evaluateTrajectory("urban", truth, estimates[i]).drift.t_rel_percent);
    std::cout << variants[i].name << ": t_rel " << drift.back() << " %" << std::endl;
  }
  for (size_t i = 1; i < variants.size(); ++i) EXPECT_LT(drift[0], drift[i]) << "against " << variants[i].name;
}

}  // namespace
}  // namespace elo
