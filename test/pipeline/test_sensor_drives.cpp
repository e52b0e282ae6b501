// Every sensor the simulator knows (config/NAME.yaml, sim::sensorNames()) renders from its configuration
// and tracks a short simulated drive with it: the urban `curves` drive from rest, sweeps distorted by the
// motion and deskewed by their per-point times, as each driver delivers them. docs/sensors.md has each
// sensor's figures. Every run of the suite drives kEverySuiteSensors (a Velodyne, a Hesai, the QT64 dome
// and a RoboSense, among the cheapest to simulate); test_sensor_drives_long (ELO_SENSOR_DRIVES_LONG,
// label pipeline-long) drives the others.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "elo/eval/evaluation.hpp"
#include "elo/pipeline/odometry.hpp"
#include "elo/sim/sensors.hpp"
#include "elo/sim/simulation.hpp"

namespace elo {
namespace {

constexpr int kFrames = 40;
const std::vector<std::string> kEverySuiteSensors = {"hdl32", "xt32m", "qt64", "helios16"};
// Endpoint error over the driven length. The sensors land between 0.1 and 1 % on this drive.
constexpr double kMaxEndpointErrorShare = 0.02;

sim::SimulationSpec driveOf(const std::string& sensor) {
  sim::SimulationSpec spec;
  sim::loadSensor(sensor, spec.config);
  spec.world = sim::WorldFamily::urban;
  spec.trajectory = sim::TrajectoryKind::curves;
  spec.frames = kFrames;
  spec.seed = 3;
  spec.lidar.deskewed = false;
  spec.lidar.time_convention = sim::TimeConvention::field;
  return spec;
}

struct DriveResult {
  double length = 0.0;          // m along the ground truth
  double endpoint_error = 0.0;  // m between the last estimated and true positions
  double rpe_rotation_deg = 0.0;
};

DriveResult drive(const sim::SimulationSpec& spec, Config config) {
  config.runtime.threads = 2;
  const sim::Simulation simulation(spec);
  Odometry odometry(config);
  std::vector<Eigen::Isometry3d> truth, estimate;
  for (int frame = 0; frame < simulation.frameCount(); ++frame) {
    const FrameResult result = odometry.process(simulation.scan(frame).cloud);
    EXPECT_TRUE(result.processed) << "frame " << frame << ": " << result.skip_reason;
    truth.push_back(simulation.sensorPose(0).inverse() * simulation.sensorPose(frame));
    estimate.push_back(result.pose);
  }
  const TrajectoryEvaluation evaluation = evaluateTrajectory(spec.config.sensor.name, truth, estimate);
  return {evaluation.length_m, (truth.back().translation() - estimate.back().translation()).norm(),
          evaluation.rpe.rotation_rmse_deg};
}

class SensorDrive : public testing::TestWithParam<std::string> {};

TEST_P(SensorDrive, TracksAShortDrive) {
  const sim::SimulationSpec spec = driveOf(GetParam());
  const DriveResult result = drive(spec, spec.config);
  std::cout << GetParam() << ": endpoint error " << result.endpoint_error << " m after " << result.length
            << " m (" << 100.0 * result.endpoint_error / result.length << " %), RPE rotation "
            << result.rpe_rotation_deg << " deg" << std::endl;
  ASSERT_GT(result.length, 10.0);
  EXPECT_LT(result.endpoint_error, kMaxEndpointErrorShare * result.length);
}

std::string sensorName(const testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name;
}

std::vector<std::string> drivenSensors() {
  std::vector<std::string> sensors;
  for (const std::string& name : sim::sensorNames()) {
    const bool every_suite =
        std::find(kEverySuiteSensors.begin(), kEverySuiteSensors.end(), name) != kEverySuiteSensors.end();
#ifdef ELO_SENSOR_DRIVES_LONG
    if (!every_suite) sensors.push_back(name);
#else
    if (every_suite) sensors.push_back(name);
#endif
  }
  return sensors;
}

INSTANTIATE_TEST_SUITE_P(Sensors, SensorDrive, testing::ValuesIn(drivenSensors()), sensorName);

}  // namespace
}  // namespace elo
