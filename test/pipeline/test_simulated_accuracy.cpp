// Accuracy gates on simulated drives with exact ground truth: a regression that makes drift 20% worse
// than the figure measured when the gate was set must fail, and the paper's ablations keep their order.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "simulated_drive.hpp"

namespace elo {
namespace {

using test::evaluateOnDrive;

// 300 scans (about 270 m) of the urban world on the `curves` drive, HDL-64E.
sim::SimulationSpec urbanCurves(uint64_t seed) {
  sim::SimulationSpec spec;
  spec.world = sim::WorldFamily::urban;
  spec.trajectory = sim::TrajectoryKind::curves;
  spec.frames = 300;
  spec.seed = seed;
  return spec;
}

struct Gate {
  RegistrationMode mode;
  double measured_t_rel;  // % on the drive below when the gate was set
  double measured_r_rel;  // deg/100 m
};

TEST(SimulatedAccuracy, UrbanDriveStaysWithinTwentyPercentOfTheMeasuredDrift) {
  // Measured on 2026-11-26 on seed 11 (266 m), after the ground patches of one ring stopped leaning:
  // frame-to-model 0.00344 % and 0.00271 deg/100 m, frame-to-frame 0.149 % and 0.175 deg/100 m (before:
  // 0.0132 % and 0.0117, 0.417 % and 0.310). Under the paper's literal closer-wins
  // (model.same_surface_distance 0) they were 0.126 % and 0.069, 0.375 % and 0.271 before both.
  const std::vector<Gate> gates = {{RegistrationMode::frame_to_model, 0.00344, 0.00271},
                                   {RegistrationMode::frame_to_frame, 0.149, 0.175}};
  std::vector<Config> configs(gates.size());
  for (size_t i = 0; i < gates.size(); ++i) configs[i].model.mode = gates[i].mode;
  const std::vector<TrajectoryEvaluation> evaluations = evaluateOnDrive(urbanCurves(11), configs);
  for (size_t i = 0; i < gates.size(); ++i) {
    const TrajectoryEvaluation& evaluation = evaluations[i];
    std::cout << (gates[i].mode == RegistrationMode::frame_to_model ? "frame-to-model" : "frame-to-frame")
              << ": t_rel " << evaluation.drift.t_rel_percent << " %, r_rel " << evaluation.drift.r_rel_deg_per_100m
              << " deg/100m over " << evaluation.length_m << " m" << std::endl;
    EXPECT_LT(evaluation.drift.t_rel_percent, 1.2 * gates[i].measured_t_rel);
    EXPECT_LT(evaluation.drift.r_rel_deg_per_100m, 1.2 * gates[i].measured_r_rel);
  }
}

// The paper's Tables II and III on seed 1: the method (fused cost terms, range-adaptive normals) must
// drift less than the SRI variants of Table II and than plain eigen normals and, in the paper's pipeline
// (the scan/model normal gate opened from our 30 to 90 degrees), than the cross product. Measured
// 2026-11-26: method 0.0037 %; SRI on all points 0.0255, SRI non-ground only 0.0217; plain eigen 0.0317;
// gate opened: range-adaptive 0.0048, cross product 0.0960 (2026-11-22, before the ground patches of one
// ring stopped leaning: 0.0123; 0.0374, 0.0229; 0.0341; 0.0117, 0.0927). With the gate at 30 degrees the
// cross product is not gated (docs/accuracy.md).
TEST(SimulatedAccuracy, TheMethodWinsTablesTwoAndThree) {
  const std::vector<std::string> names = {"method", "SRI on all points", "SRI non-ground only",
                                          "plain eigen normals", "range-adaptive, gate opened",
                                          "cross product, gate opened"};
  std::vector<Config> configs(names.size());
  configs[1].registration.terms = CostTerms::spherical_all;
  configs[2].registration.terms = CostTerms::spherical_nonground;
  configs[3].normals.method = NormalMethod::eigen;
  configs[4].registration.max_normal_angle_deg = 90.0;
  configs[5].registration.max_normal_angle_deg = 90.0;
  configs[5].normals.method = NormalMethod::cross_product;
  const std::vector<TrajectoryEvaluation> evaluations = evaluateOnDrive(urbanCurves(1), configs);
  for (size_t i = 0; i < names.size(); ++i) {
    std::cout << names[i] << ": t_rel " << evaluations[i].drift.t_rel_percent << " %" << std::endl;
  }
  for (size_t i = 1; i <= 3; ++i) {
    EXPECT_LT(evaluations[0].drift.t_rel_percent, evaluations[i].drift.t_rel_percent) << "against " << names[i];
  }
  EXPECT_LT(evaluations[4].drift.t_rel_percent, evaluations[5].drift.t_rel_percent);
}

}  // namespace
}  // namespace elo
