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

  // Measured on 2026-11-22 (266 m): frame-to-model 0.0132 % and 0.0117 deg/100 m, frame-to-frame
  // 0.417 % and 0.310 deg/100 m. Under the paper's literal closer-wins (model.same_surface_distance 0)
  // they were 0.126 % and 0.069, 0.375 % and 0.271.
  const std::vector<Gate> gates = {{RegistrationMode::frame_to_model, 0.0132, 0.0117},
                                   {RegistrationMode::frame_to_frame, 0.417, 0.310}};
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

// The paper's Tables II and III on a 300-scan urban drive, seed 1: the method (fused cost terms,
// range-adaptive normals) must drift less than the SRI variants of Table II and than plain eigen normals.
// Measured 2026-11-22: method 0.0123 %; SRI on all points 0.0374, SRI non-ground only 0.0229; plain eigen
// 0.0341. The cross product (0.0137 here) is not gated: on other seeds it beats range-adaptive normals
// (README, Accuracy).
TEST(SimulatedAccuracy, TheMethodWinsTableTwoAndBeatsPlainEigenNormals) {
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
  std::vector<Variant> variants(4);
  variants[0].name = "method";
  variants[1].name = "SRI on all points";
  variants[1].config.registration.terms = CostTerms::spherical_all;
  variants[2].name = "SRI non-ground only";
  variants[2].config.registration.terms = CostTerms::spherical_nonground;
  variants[3].name = "plain eigen normals";
  variants[3].config.normals.method = NormalMethod::eigen;
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
