// Deskew gates (issue 15) on simulated drives whose sensor moves during each 0.1 s sweep, as a spinning
// LiDAR on a car does, with exact ground truth and no moving cars. With deskew, frame-to-model drift stays
// within 1.5 times the same drive's drift with instantaneous scans, for both time sources: the cloud's
// per-point times (`field`, pose at the stamp, the sweep's start) and times from the azimuth (`azimuth`,
// KITTI's convention, pose at mid-sweep). Frame-to-frame drift in the plane (horizontal t_rel), where the
// sweep's distortion acts, is lower with deskew than without: the VLP-16's frame-to-frame t_rel is height
// from a ground model of one scan's rings, 5.5 % with deskew and without.
#include <gtest/gtest.h>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "elo/eval/evaluation.hpp"
#include "elo/pipeline/odometry.hpp"
#include "elo/sim/sensors.hpp"
#include "elo/sim/simulation.hpp"
#include "simulated_drive.hpp"

namespace elo {
namespace {

using test::evaluateOnDrive;

// The `curves` drive from rest: urban up to 10 m/s (200 scans, 166 m), highway up to 25 m/s (160 scans,
// 190 m), turning at the comfortable radius, so that the sweep's rotation is corrected as well as its
// translation. (The `loop` drive, at speed from the first scan, is lost on its first scans by the VLP-16
// even without distortion: the prior starts at rest.)
struct DistortedDrive {
  sim::WorldFamily world;
  std::string sensor;
  int frames;
};

std::string nameOf(const DistortedDrive& drive) { return sim::worldName(drive.world) + "_" + drive.sensor; }

// gtest names a failing drive by this rather than by its bytes.
void PrintTo(const DistortedDrive& drive, std::ostream* out) { *out << nameOf(drive) << ", " << drive.frames << " scans"; }

sim::SimulationSpec specOf(const DistortedDrive& drive, bool distorted) {
  sim::SimulationSpec spec;
  spec.world = drive.world;
  spec.trajectory = sim::TrajectoryKind::curves;
  spec.frames = drive.frames;
  spec.seed = 7;
  sim::loadSensor(drive.sensor, spec.config);
  spec.lidar.deskewed = !distorted;
  spec.lidar.time_convention = sim::TimeConvention::field;
  return spec;
}

// The sensor's own configuration, as a user runs it, with the mode and time source of the run.
Config configOf(const sim::SimulationSpec& spec, RegistrationMode mode, TimeSource source) {
  Config config = spec.config;
  config.model.mode = mode;
  config.deskew.time_source = source;
  return config;
}

// One distorted drive as both conventions deliver it, every run against its ground truth: field runs
// get the simulated scans (times from the sweep's start, its stamp); azimuth runs get the same firings as
// the azimuth convention writes them, without times and stamped at mid-sweep, and the ground truth there.
struct DistortedRuns {
  std::vector<TrajectoryEvaluation> field;
  std::vector<TrajectoryEvaluation> azimuth;
};

DistortedRuns evaluateDistorted(const sim::SimulationSpec& field_spec, const std::vector<Config>& field_configs,
                                const std::vector<Config>& azimuth_configs) {
  sim::SimulationSpec azimuth_spec = field_spec;
  azimuth_spec.lidar.time_convention = sim::TimeConvention::azimuth;
  const sim::Simulation field(field_spec);
  const sim::Simulation azimuth(azimuth_spec);  // its ground truth and stamps; its sweeps are field's
  std::vector<std::unique_ptr<Odometry>> field_runs, azimuth_runs;
  for (const Config& config : field_configs) field_runs.push_back(std::make_unique<Odometry>(config));
  for (const Config& config : azimuth_configs) azimuth_runs.push_back(std::make_unique<Odometry>(config));
  std::vector<Eigen::Isometry3d> field_truth, azimuth_truth;
  std::vector<std::vector<Eigen::Isometry3d>> field_poses(field_runs.size()), azimuth_poses(azimuth_runs.size());
  const auto runAll = [](std::vector<std::unique_ptr<Odometry>>& runs, const PointCloud& cloud,
                         std::vector<std::vector<Eigen::Isometry3d>>& poses) {
    for (size_t i = 0; i < runs.size(); ++i) {
      const FrameResult result = runs[i]->process(cloud);
      EXPECT_TRUE(result.processed) << "run " << i << ": " << result.skip_reason;
      poses[i].push_back(result.pose);
    }
  };
  for (int frame = 0; frame < field.frameCount(); ++frame) {
    PointCloud cloud = field.scan(frame).cloud;
    field_truth.push_back(field.sensorPose(0).inverse() * field.sensorPose(frame));
    azimuth_truth.push_back(azimuth.sensorPose(0).inverse() * azimuth.sensorPose(frame));
    runAll(field_runs, cloud, field_poses);
    cloud.time.clear();
    cloud.stamp = azimuth.stamp(frame);
    runAll(azimuth_runs, cloud, azimuth_poses);
  }
  DistortedRuns runs;
  for (const auto& poses : field_poses) runs.field.push_back(evaluateTrajectory("field", field_truth, poses));
  for (const auto& poses : azimuth_poses) runs.azimuth.push_back(evaluateTrajectory("azimuth", azimuth_truth, poses));
  return runs;
}

void print(const std::string& drive, const std::string& run, const TrajectoryEvaluation& evaluation) {
  std::cout << drive << ", " << run << ": t_rel " << evaluation.drift.t_rel_percent << " % (horizontal "
            << evaluation.drift.t_rel_horizontal_percent << " %), r_rel " << evaluation.drift.r_rel_deg_per_100m
            << " deg/100m over " << evaluation.length_m << " m (" << evaluation.drift.segments << " segments)"
            << std::endl;
}

class DeskewAccuracy : public testing::TestWithParam<DistortedDrive> {};

TEST_P(DeskewAccuracy, DeskewedDriftStaysNearTheInstantaneousDrift) {
  const auto start = std::chrono::steady_clock::now();
  const DistortedDrive& drive = GetParam();
  const std::string name = nameOf(drive);
  const auto f2m = RegistrationMode::frame_to_model;
  const auto f2f = RegistrationMode::frame_to_frame;

  const sim::SimulationSpec instantaneous_spec = specOf(drive, false);
  const TrajectoryEvaluation instantaneous =
      evaluateOnDrive(instantaneous_spec, {configOf(instantaneous_spec, f2m, TimeSource::none)}).front();
  print(name, "instantaneous scans, f2m", instantaneous);

  const sim::SimulationSpec distorted_spec = specOf(drive, true);
  const DistortedRuns distorted =
      evaluateDistorted(distorted_spec,
                        {configOf(distorted_spec, f2m, TimeSource::field), configOf(distorted_spec, f2f, TimeSource::field),
                         configOf(distorted_spec, f2f, TimeSource::none)},
                        {configOf(distorted_spec, f2m, TimeSource::azimuth),
                         configOf(distorted_spec, f2f, TimeSource::azimuth), configOf(distorted_spec, f2f, TimeSource::none)});
  const std::vector<std::string> runs = {"deskewed f2m", "deskewed f2f", "not deskewed f2f"};
  for (size_t i = 0; i < runs.size(); ++i) {
    print(name, "field times, " + runs[i], distorted.field[i]);
    print(name, "azimuth times, " + runs[i], distorted.azimuth[i]);
  }

  ASSERT_GT(instantaneous.drift.segments, 0u) << "the drive is shorter than KITTI's shortest segment";
  const double bound = 1.5 * instantaneous.drift.t_rel_percent;
  EXPECT_LE(distorted.field[0].drift.t_rel_percent, bound) << "field times, f2m";
  EXPECT_LE(distorted.azimuth[0].drift.t_rel_percent, bound) << "azimuth times, f2m";
  EXPECT_LT(distorted.field[1].drift.t_rel_horizontal_percent, distorted.field[2].drift.t_rel_horizontal_percent)
      << "field times, f2f";
  EXPECT_LT(distorted.azimuth[1].drift.t_rel_horizontal_percent, distorted.azimuth[2].drift.t_rel_horizontal_percent)
      << "azimuth times, f2f";
  std::cout << name << ": " << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s" << std::endl;
}

// Built twice (test/pipeline/CMakeLists.txt): the VLP-16 drive in every run of the suite, the HDL-64E's,
// about five times the points, labelled long. The VLP-16 loses the highway drive even on instantaneous
// scans (101 % t_rel, seed 7): too few of its 16 rings meet the open road's sparse features.
#ifdef ELO_DESKEW_GATES_LONG
INSTANTIATE_TEST_SUITE_P(Hdl64, DeskewAccuracy,
                         testing::Values(DistortedDrive{sim::WorldFamily::urban, "hdl64", 200},
                                         DistortedDrive{sim::WorldFamily::highway, "hdl64", 160}),
                         [](const auto& info) { return nameOf(info.param); });
#else
INSTANTIATE_TEST_SUITE_P(Vlp16, DeskewAccuracy, testing::Values(DistortedDrive{sim::WorldFamily::urban, "vlp16", 200}),
                         [](const auto& info) { return nameOf(info.param); });

// KITTI-raw's stamps: a sensor turning at 9.66 Hz, its scans 0.1035 s apart, recorded with stamps rounded
// to 10 ms (0.10 and 0.11 s apart), and a configuration that says 10 Hz. With azimuth times the motion is
// measured over whole sweep periods (motionInterval()), so the rounding changes no pose; measured over
// the stamps' intervals, every sweep was deskewed 5-10 % wrong, alternately (docs/real_drives.md).
TEST(DeskewTiming, StampsRoundedTo10MsChangeNoPose) {
  sim::SimulationSpec spec = specOf(DistortedDrive{sim::WorldFamily::urban, "vlp16", 60}, true);
  spec.lidar.time_convention = sim::TimeConvention::azimuth;
  spec.config.sensor.rotation_rate_hz = 9.66;
  sim::SimulationSpec rounded_spec = spec;
  rounded_spec.stamp_rounding = 0.01;
  const sim::Simulation exact(spec);
  const sim::Simulation rounded(rounded_spec);
  Config config;
  sim::loadSensor("vlp16", config);
  config.deskew.time_source = TimeSource::azimuth;
  Odometry exact_run(config);
  Odometry rounded_run(config);
  double largest_gap = 0.0;
  for (int frame = 0; frame < spec.frames; ++frame) {
    const FrameResult a = exact_run.process(exact.scan(frame).cloud);
    const FrameResult b = rounded_run.process(rounded.scan(frame).cloud);
    ASSERT_TRUE(a.processed && b.processed) << "frame " << frame;
    largest_gap = std::max(largest_gap, (a.pose.translation() - b.pose.translation()).norm());
  }
  EXPECT_NE(exact.recordedStamp(1) - exact.recordedStamp(0), rounded.recordedStamp(1) - rounded.recordedStamp(0));
  EXPECT_LT(largest_gap, 1e-9) << "the rounded stamps moved a pose";
}
#endif

}  // namespace
}  // namespace elo
