// Sparse sensors (issue 31) on a simulated urban drive, the sensor configured by its config/<sensor>.yaml:
// the heading error's sign, the horizontal drift and the heading slip. A drive and its mirror image (left
// turns made right ones) must drift in heading by opposite amounts, so that their mean per-scan heading
// error, the pipeline's one-signed part, is near zero. And the targets on thin stretches and
// around a roundabout. Drives of 140-790 m, run in every test run; test_sparse_sensors_long
// (ELO_SPARSE_SENSORS_LONG, label pipeline-long) drives every other sparse sensor around the roundabout.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "elo/eval/evaluation.hpp"
#include "elo/pipeline/odometry.hpp"
#include "elo/sim/sensors.hpp"
#include "elo/sim/simulation.hpp"

namespace elo {
namespace {

constexpr double kDegrees = 180.0 / M_PI;

double yawOf(const Eigen::Isometry3d& pose) { return std::atan2(pose.linear()(1, 0), pose.linear()(0, 0)); }

struct SparseDrive {
  TrajectoryEvaluation evaluation;
  double mean_heading_drift_deg = 0.0;  // per scan: the estimated increment's yaw minus the truth's
  double largest_slip_deg = 0.0;        // the largest heading change against the truth over any 10 scans
  double turned_deg = 0.0;              // the truth's heading change over the drive
};

// The odometry, configured as config/<sensor>.yaml, over the simulated drive of that sensor.
SparseDrive drive(const std::string& sensor, sim::SimulationSpec spec) {
  sim::loadSensor(sensor, spec.config);
  const sim::Simulation simulation(spec);
  Odometry odometry(spec.config);
  std::vector<Eigen::Isometry3d> truth;
  std::vector<Eigen::Isometry3d> estimate;
  const Eigen::Isometry3d start = simulation.sensorPose(0);
  for (int frame = 0; frame < simulation.frameCount(); ++frame) {
    const FrameResult result = odometry.process(simulation.scan(frame).cloud);
    EXPECT_TRUE(result.processed) << sensor << ", frame " << frame << ": " << result.skip_reason;
    truth.push_back(start.inverse() * simulation.sensorPose(frame));
    estimate.push_back(result.pose);
  }
  SparseDrive result;
  result.evaluation = evaluateTrajectory(sensor, truth, estimate);
  std::vector<double> heading_error;
  for (size_t i = 0; i < truth.size(); ++i) heading_error.push_back(yawOf(truth[i].inverse() * estimate[i]));
  constexpr size_t kSlipScans = 10;
  for (size_t i = 0; i + kSlipScans < truth.size(); ++i) {
    result.largest_slip_deg =
        std::max(result.largest_slip_deg, kDegrees * std::abs(heading_error[i + kSlipScans] - heading_error[i]));
  }
  for (size_t i = 1; i < truth.size(); ++i) {
    const Eigen::Isometry3d true_increment = truth[i - 1].inverse() * truth[i];
    const Eigen::Isometry3d increment = estimate[i - 1].inverse() * estimate[i];
    result.mean_heading_drift_deg += kDegrees * yawOf(true_increment.inverse() * increment);
    result.turned_deg += kDegrees * yawOf(true_increment);
  }
  result.mean_heading_drift_deg /= static_cast<double>(truth.size() - 1);
  const DriftError& drift = result.evaluation.drift;
  std::cout << sensor << (spec.mirrored ? " mirrored" : "") << ", " << simulation.frameCount() << " scans, "
            << result.evaluation.length_m << " m, turned " << result.turned_deg << " deg: t_rel "
            << drift.t_rel_percent << " %, horizontal " << drift.t_rel_horizontal_percent << " %, r_rel "
            << drift.r_rel_deg_per_100m << " deg/100m, heading drift " << result.mean_heading_drift_deg
            << " deg/scan, largest slip over 10 scans " << result.largest_slip_deg << " deg" << std::endl;
  return result;
}

sim::SimulationSpec driveIn(sim::WorldFamily world, sim::TrajectoryKind trajectory, int frames, uint64_t seed,
                            bool mirrored = false) {
  sim::SimulationSpec spec;
  spec.world = world;
  spec.trajectory = trajectory;
  spec.frames = frames;
  spec.seed = seed;
  spec.mirrored = mirrored;
  return spec;
}

sim::SimulationSpec urbanRoundabout(uint64_t seed) {
  return driveIn(sim::WorldFamily::urban, sim::TrajectoryKind::roundabout, 1050, seed);
}

#ifndef ELO_SPARSE_SENSORS_LONG
sim::SimulationSpec curvesIn(sim::WorldFamily world, int frames, uint64_t seed, bool mirrored = false) {
  return driveIn(world, sim::TrajectoryKind::curves, frames, seed, mirrored);
}

sim::SimulationSpec urbanCurves(int frames, uint64_t seed, bool mirrored = false) {
  return curvesIn(sim::WorldFamily::urban, frames, seed, mirrored);
}

// The targets for the VLP-16: t_rel and horizontal t_rel 0.2 %, r_rel 0.2 deg/100 m, no heading
// slip over 0.5 deg within 10 scans.
void expectVlp16Targets(const SparseDrive& vlp16) {
  EXPECT_LT(vlp16.evaluation.drift.t_rel_percent, 0.2);
  EXPECT_LT(vlp16.evaluation.drift.t_rel_horizontal_percent, 0.2);
  EXPECT_LT(vlp16.evaluation.drift.r_rel_deg_per_100m, 0.2);
  EXPECT_LT(vlp16.largest_slip_deg, 0.5);
}

// 200 VLP-16 scans (166 m, turning 45 degrees) and their mirror image. Until the model update's equal-age
// offers fell to the lower column, both drifted clockwise: -0.00100 and -0.00121 deg/scan (pair mean
// -0.0011). Measured now (with the fading prior of degeneracy.hpp, the ground patches of one ring level
// across it, plane_fit.hpp, and config/vlp16.yaml's outlier distance and weight): -0.000049 and
// +0.000060 (pair mean +0.000005), horizontal t_rel 0.020 and 0.021 %, largest slip over 10 scans 0.009
// deg, t_rel 0.047 and 0.049 % (0.24 % while the ground patches leaned), r_rel 0.035 and 0.036 deg/100 m;
// the targets are 0.2 % and 0.2 deg/100 m.
TEST(SparseSensors, HeadingDriftHasNoSignTurningLeftOrRight) {
  const SparseDrive left = drive("vlp16", urbanCurves(200, 3));
  const SparseDrive right = drive("vlp16", urbanCurves(200, 3, true));
  EXPECT_GT(left.turned_deg, 40.0);
  EXPECT_LT(right.turned_deg, -40.0);
  EXPECT_LT(std::abs(0.5 * (left.mean_heading_drift_deg + right.mean_heading_drift_deg)), 0.0003);
  for (const SparseDrive* run : {&left, &right}) {
    expectVlp16Targets(*run);
    EXPECT_LT(run->evaluation.drift.t_rel_horizontal_percent, 0.06);
  }
}

// Thin stretches, where the scan holds little but the road: a country road between fields with a few
// poles, trees and hedges (250 m), and a car park's open lot (141 m). The targets: the VLP-16's
// above, the OS1-64 at horizontal t_rel 0.03 %. Measured: VLP-16 country 0.060 % / 0.046 % / 0.030,
// parking 0.094 % / 0.025 % / 0.098; OS1-64 country horizontal 0.012 % (t_rel 0.015 %).
TEST(SparseSensors, ThinStretchesHoldTheTargets) {
  expectVlp16Targets(drive("vlp16", curvesIn(sim::WorldFamily::country, 200, 3)));
  expectVlp16Targets(drive("vlp16", curvesIn(sim::WorldFamily::parking, 300, 3)));
  const SparseDrive os1 = drive("os1-64", curvesIn(sim::WorldFamily::country, 200, 3));
  EXPECT_LT(os1.evaluation.drift.t_rel_horizontal_percent, 0.03);
}

// The VLP-16 around the urban roundabout, `make accuracy`'s drive (seed 7, 1050 scans, 790 m from rest:
// four times through a roundabout of 2 deg a scan, straights between). The targets. Measured:
// t_rel 0.036 %, horizontal 0.023 %, r_rel 0.026 deg/100 m, largest slip over 10 scans 0.026 deg (0.212 %
// and 0.31 deg before config/vlp16.yaml's outlier distance and weight). Seeds 3 and 11: 0.041 and 0.044 %.
TEST(SparseSensors, Vlp16RoundaboutHoldsTheTargets) {
  const SparseDrive vlp16 = drive("vlp16", urbanRoundabout(7));
  EXPECT_GT(vlp16.evaluation.length_m, 780.0);
  expectVlp16Targets(vlp16);
}
#else
// Every other sensor whose beams lie 1 deg or more apart, configured as shipped, around the same
// roundabout: each needs its config's normals.outlier_distance and takes its non-ground weight 0.5
// (docs/accuracy.md, "every sensor's normals at range"). Measured t_rel % as shipped (with the paper's
// sigma_r 0.5 m and w1 0.7): xt32 0.011 (0.016), xt32m 0.015 (0.113), hdl32 0.019 (0.027), os0-64 0.017
// (0.126), qt64 0.025 (0.155), xt16 0.034 (0.435), helios16 0.028 (0.129), helios5515 0.018 (0.044); the
// Bpearl, a hemisphere that sees little but the road, 0.187 (lost). Bounds: 0.06 % t_rel, under a third
// of the VLP-16's target (0.2 %), which five of them broke with the paper's values; the Bpearl 0.3 %.
class SparseSensorRoundabout : public testing::TestWithParam<const char*> {};

TEST_P(SparseSensorRoundabout, HoldsItsHeadingAndDrift) {
  const std::string sensor = GetParam();
  const SparseDrive run = drive(sensor, urbanRoundabout(7));
  const double bound = sensor == "bpearl" ? 0.3 : 0.06;
  EXPECT_GT(run.evaluation.length_m, 780.0);
  EXPECT_LT(run.evaluation.drift.t_rel_percent, bound);
  EXPECT_LT(run.evaluation.drift.t_rel_horizontal_percent, bound);
  EXPECT_LT(run.evaluation.drift.r_rel_deg_per_100m, 0.2);
  EXPECT_LT(run.largest_slip_deg, 0.5);
}

INSTANTIATE_TEST_SUITE_P(Sensors, SparseSensorRoundabout,
                         testing::Values("xt32", "xt32m", "hdl32", "os0-64", "qt64", "xt16", "helios16",
                                         "helios5515", "bpearl"),
                         [](const testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });
#endif

}  // namespace
}  // namespace elo
