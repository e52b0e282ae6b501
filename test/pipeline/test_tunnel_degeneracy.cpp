// Degeneracy handling on a simulated tunnel: once inside, nothing constrains the forward translation.
// Without the handling, Gauss-Newton follows the noise along it and the trajectory runs away; with it,
// the scans are flagged degenerate along x and the forward motion continues at the velocity of the
// approach, so drift stays as low as on an open road.
#include <gtest/gtest.h>

#include "elo/eval/evaluation.hpp"
#include "elo/pipeline/odometry.hpp"
#include "elo/sim/simulation.hpp"

namespace elo {
namespace {

struct OdometryRun {
  OdometryRun(const char* name_, double threshold) : name(name_), odometry(configWithThreshold(threshold)) {}
  static Config configWithThreshold(double threshold) {
    Config config;
    config.registration.degeneracy_threshold = threshold;
    return config;
  }

  const char* name;
  Odometry odometry;
  std::vector<Eigen::Isometry3d> poses;
  size_t degenerate_before_portal = 0;
  size_t degenerate_inside = 0;
  size_t scans_inside = 0;
};

// 160 scans (169 m) of the tunnel world's straight drive, HDL-64E, seed 3: up to cruise speed on the open
// approach, through the portal 100 m after the start at scan 115, then 69 m inside.
TEST(TunnelDegeneracy, HandlingKeepsTheForwardMotionThatTheTunnelCannotObserve) {
  sim::SimulationSpec spec;
  spec.world = sim::WorldFamily::tunnel;
  spec.trajectory = sim::TrajectoryKind::straight;
  spec.frames = 160;
  spec.seed = 3;
  const sim::Simulation simulation(spec);
  constexpr double kPortal = 100.0;
  // Past the portal by this much, the mouth behind the sensor no longer constrains anything.
  constexpr double kDeepInside = kPortal + 10.0;

  OdometryRun handled("with handling", RegistrationConfig().degeneracy_threshold);
  OdometryRun unhandled("without", 0.0);
  const std::vector<OdometryRun*> runs = {&handled, &unhandled};
  std::vector<Eigen::Isometry3d> truth;
  const Eigen::Isometry3d start = simulation.sensorPose(0);
  for (int frame = 0; frame < simulation.frameCount(); ++frame) {
    const PointCloud cloud = simulation.scan(frame).cloud;
    truth.push_back(start.inverse() * simulation.sensorPose(frame));
    const double travelled = truth.back().translation().x();
    for (OdometryRun* run_pointer : runs) {
      OdometryRun& run = *run_pointer;
      const FrameResult result = run.odometry.process(cloud);
      ASSERT_TRUE(result.processed) << run.name << ", frame " << frame << ": " << result.skip_reason;
      run.poses.push_back(result.pose);
      const Degeneracy& degeneracy = result.registration.degeneracy;
      if (travelled < kPortal - 10.0 && degeneracy.any()) ++run.degenerate_before_portal;
      if (travelled > kDeepInside) {
        ++run.scans_inside;
        if (degeneracy.any() && degeneracy.describe() == "x") ++run.degenerate_inside;
      }
    }
  }

  std::vector<double> drift;  // t_rel %, per run
  for (const OdometryRun* run : runs) {
    const TrajectoryEvaluation evaluation = evaluateTrajectory("tunnel", truth, run->poses);
    drift.push_back(evaluation.drift.t_rel_percent);
    const double end_error = (truth.back().inverse() * run->poses.back()).translation().norm();
    std::cout << run->name << ": t_rel " << evaluation.drift.t_rel_percent << " %, r_rel "
              << evaluation.drift.r_rel_deg_per_100m << " deg/100m, end error " << end_error << " m over "
              << evaluation.length_m << " m; degenerate along x on " << run->degenerate_inside << " of "
              << run->scans_inside << " scans inside" << std::endl;
  }
  // The open approach is constrained along x close to the threshold: its two smallest shares were 0.0099
  // and 0.0101 (2026-11-22), so one of its scans may be flagged, and its x then follows the prior.
  EXPECT_LE(handled.degenerate_before_portal, 1u) << "the open approach is constrained";
  EXPECT_GT(handled.scans_inside, 30u);
  EXPECT_EQ(handled.degenerate_inside, handled.scans_inside) << "every scan deep inside lacks its forward motion";
  EXPECT_EQ(unhandled.degenerate_inside, 0u) << "threshold 0 turns the handling off";
  // Measured: with the handling 0.038 % (0.11 m off at the end; 0.027 % and 0.08 m since the ground test's
  // rise tolerance; 0.0132 % and 0.04 m since issue 31's prior that fades in and the model's hashed ties),
  // without 1.3-20 % (24-179 m off: Gauss-Newton steps of metres along x, driven by noise, so that figure
  // varies from build to build and with any change to the features). A regression by half fails the
  // first; the second only has to show the run away, at over 20 times the first's bound.
  EXPECT_LT(drift[0], 1.5 * 0.0132);
  EXPECT_GT(drift[1], 0.4) << "without the handling the tunnel is expected to run away";
}

}  // namespace
}  // namespace elo
