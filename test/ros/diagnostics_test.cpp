// The diagnostics' summary and counters. No ROS master.
#include <gtest/gtest.h>

#include "diagnostics.hpp"

namespace {

std::string valueOf(const diagnostic_updater::DiagnosticStatusWrapper& status, const std::string& key) {
  for (const auto& entry : status.values) {
    if (entry.key == key) return entry.value;
  }
  return "<missing>";
}

elo::FrameResult processedScan(double total_ms) {
  elo::FrameResult result;
  result.processed = true;
  result.times.total = total_ms;
  result.registration.iterations = 3;
  result.registration.last.nonground.candidates = 100;
  result.registration.last.nonground.inliers = 80;
  return result;
}

// The status reported after one more cloud received and processed as `result`, 65 ms after it arrived.
diagnostic_updater::DiagnosticStatusWrapper statusAfterScan(elo_ros::PipelineStatistics& statistics,
                                                            const elo::FrameResult& result) {
  statistics.cloudReceived();
  statistics.scanProcessed(result, 65.0);
  diagnostic_updater::DiagnosticStatusWrapper status;
  statistics.report(status);
  return status;
}

TEST(RosDiagnostics, QuietWindowIsOk) {
  elo_ros::PipelineStatistics statistics;
  const diagnostic_updater::DiagnosticStatusWrapper status = statusAfterScan(statistics, processedScan(60.0));
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::OK);
  EXPECT_EQ(valueOf(status, "processing time mean (ms)"), "60");
  EXPECT_EQ(valueOf(status, "latency max (ms)"), "65");
  EXPECT_EQ(valueOf(status, "non-ground inlier ratio"), "0.8");
  EXPECT_EQ(valueOf(status, "scans processed"), "1");
}

// A start in motion is counted; one the scans could not tell apart warns for the window it fell in.
TEST(RosDiagnostics, StartSearchesAreCountedAndAnAmbiguousOneWarns) {
  elo_ros::PipelineStatistics statistics;
  elo::FrameResult searched = processedScan(60.0);
  searched.start_search.searched = true;
  const diagnostic_updater::DiagnosticStatusWrapper clear = statusAfterScan(statistics, searched);
  EXPECT_EQ(clear.level, diagnostic_msgs::DiagnosticStatus::OK) << clear.message;
  EXPECT_EQ(valueOf(clear, "start searches"), "1");

  searched.start_search.ambiguous = true;
  const diagnostic_updater::DiagnosticStatusWrapper ambiguous = statusAfterScan(statistics, searched);
  EXPECT_EQ(ambiguous.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(ambiguous.message.find("1 ambiguous start"), std::string::npos) << ambiguous.message;
  EXPECT_EQ(valueOf(ambiguous, "start searches"), "2");
  EXPECT_EQ(valueOf(ambiguous, "ambiguous starts"), "1");
}

// A gap between scans, its motion searched, is counted; not a problem in itself (the node warns in its log).
TEST(RosDiagnostics, GapsAreCounted) {
  elo_ros::PipelineStatistics statistics;
  elo::FrameResult across = processedScan(60.0);
  across.gap = 2.1;
  across.start_search.searched = true;
  const diagnostic_updater::DiagnosticStatusWrapper status = statusAfterScan(statistics, across);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::OK) << status.message;
  EXPECT_EQ(valueOf(status, "gaps searched"), "1");
  EXPECT_EQ(valueOf(statusAfterScan(statistics, processedScan(60.0)), "gaps searched"), "1");
}

// A refused registration is lost: ERROR while it lasts, counted by reason; a recovery goes back to OK.
TEST(RosDiagnostics, ARefusedRegistrationIsAnErrorUntilTheTrackRecovers) {
  elo_ros::PipelineStatistics statistics;
  elo::FrameResult refused = processedScan(60.0);
  refused.refusal = elo::refusal::kAccelerates;
  const diagnostic_updater::DiagnosticStatusWrapper lost = statusAfterScan(statistics, refused);
  EXPECT_EQ(lost.level, diagnostic_msgs::DiagnosticStatus::ERROR) << lost.message;
  EXPECT_NE(lost.message.find("lost"), std::string::npos) << lost.message;
  EXPECT_EQ(valueOf(lost, std::string("registrations refused: ") + elo::refusal::kAccelerates), "1");

  elo::FrameResult recovered = processedScan(60.0);
  recovered.recovered = true;
  const diagnostic_updater::DiagnosticStatusWrapper again = statusAfterScan(statistics, recovered);
  EXPECT_EQ(again.level, diagnostic_msgs::DiagnosticStatus::OK) << again.message;
  EXPECT_EQ(valueOf(again, "recoveries"), "1");
}

TEST(RosDiagnostics, DropsRejectionsAndSkipsWarnAndAreCounted) {
  elo_ros::PipelineStatistics statistics;
  statistics.cloudReceived();
  statistics.cloudsDropped(2);
  statistics.cloudRejected("truncated data");
  statistics.scanSkipped("too few valid points");
  diagnostic_updater::DiagnosticStatusWrapper status;
  statistics.report(status);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(status.message.find("2 dropped"), std::string::npos) << status.message;
  EXPECT_NE(status.message.find("1 rejected"), std::string::npos) << status.message;
  EXPECT_EQ(valueOf(status, "clouds rejected: truncated data"), "1");
  EXPECT_EQ(valueOf(status, "scans skipped: too few valid points"), "1");

  diagnostic_updater::DiagnosticStatusWrapper next;
  statistics.report(next);
  EXPECT_EQ(next.message, "no clouds received") << "a new window starts empty";
  EXPECT_EQ(valueOf(next, "scans dropped"), "2") << "totals stay";
}

TEST(RosDiagnostics, RestartsWarnAndAreCountedByReason) {
  elo_ros::PipelineStatistics statistics;
  statistics.cloudReceived();
  statistics.odometryRestarted("gap longer than model.time_window");
  statistics.scanProcessed(processedScan(60.0), 65.0);
  diagnostic_updater::DiagnosticStatusWrapper status;
  statistics.report(status);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(status.message.find("1 odometry restarts"), std::string::npos) << status.message;
  EXPECT_EQ(valueOf(status, "odometry restarts: gap longer than model.time_window"), "1");
}

TEST(RosDiagnostics, UnusablePerPointTimesWarnAndAreCountedByReason) {
  elo_ros::PipelineStatistics statistics;
  elo::FrameResult instantaneous = processedScan(60.0);
  instantaneous.time_warning = "no per-point times: taken as instantaneous";
  const diagnostic_updater::DiagnosticStatusWrapper status = statusAfterScan(statistics, instantaneous);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(status.message.find("1 scans with unusable per-point times"), std::string::npos) << status.message;
  EXPECT_EQ(valueOf(status, "per-point times: no per-point times: taken as instantaneous"), "1");
}

TEST(RosDiagnostics, DegenerateScansWarnWhileTheyLastAndAreCounted) {
  elo_ros::PipelineStatistics statistics;
  elo::FrameResult tunnel = processedScan(60.0);
  elo::Matrix6d hessian = (elo::Vector6d() << 0, 1, 1, 50, 50, 50).finished().asDiagonal();  // x unconstrained
  tunnel.registration.degeneracy = *elo::analyseDegeneracy(hessian, 0.005);
  const diagnostic_updater::DiagnosticStatusWrapper inside = statusAfterScan(statistics, tunnel);
  EXPECT_EQ(inside.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(inside.message, "latest scan degenerate along x");
  EXPECT_EQ(valueOf(inside, "degenerate directions"), "x");
  EXPECT_EQ(valueOf(inside, "scans degenerate"), "1");

  const diagnostic_updater::DiagnosticStatusWrapper outside = statusAfterScan(statistics, processedScan(60.0));
  EXPECT_EQ(outside.level, diagnostic_msgs::DiagnosticStatus::OK) << outside.message;
  EXPECT_EQ(valueOf(outside, "degenerate directions"), "none");
  EXPECT_EQ(valueOf(outside, "scans degenerate"), "1") << "the total stays";
}

}  // namespace

namespace {

// `count` Imu messages `period` seconds apart from `start`, then the window's status.
diagnostic_updater::DiagnosticStatusWrapper imuStatusAfter(elo_ros::ImuStatistics& statistics, int count,
                                                           double period, double start = 0.0) {
  for (int i = 0; i < count; ++i) statistics.messageReceived(start + i * period);
  diagnostic_updater::DiagnosticStatusWrapper status;
  statistics.report(status);
  return status;
}

}  // namespace

// The IMU's status: OK at its rate; WARN while it is silent, under imu.min_rate_hz (by the stamps), or in
// a window where scans fell back, samples were dropped or messages unused, each counted by reason.
TEST(RosDiagnostics, ImuAtItsRateIsOkAndSilenceSlownessAndFallbacksWarn) {
  elo_ros::ImuStatistics statistics(50.0);
  elo::ImuStatus core;
  core.samples_taken = 200;
  core.gyro_bias = {M_PI / 180.0, 0.0, -0.5 * M_PI / 180.0};
  statistics.update(core);
  const diagnostic_updater::DiagnosticStatusWrapper steady = imuStatusAfter(statistics, 201, 0.005);
  EXPECT_EQ(steady.level, diagnostic_msgs::DiagnosticStatus::OK) << steady.message;
  EXPECT_EQ(valueOf(steady, "IMU rate (Hz)"), "200");
  EXPECT_EQ(valueOf(steady, "Imu messages received"), "201");
  EXPECT_EQ(valueOf(steady, "IMU samples taken"), "200");
  EXPECT_EQ(valueOf(steady, "gyro bias (deg/s)"), "1, 0, -0.5");
  EXPECT_EQ(valueOf(steady, "gravity in the odometry frame (m/s^2)"), "not estimated yet");
  EXPECT_EQ(valueOf(steady, "tilt against gravity (deg)"), "not measured yet");
  core.gravity_known = true;
  core.gravity = {0.0, -0.5, -9.79};
  core.accel_bias = {0.05, 0.0, -0.02};
  core.accel_gated = 3;
  core.tilt_deg = 0.25;
  core.tilt_held = 4;
  statistics.update(core);
  const diagnostic_updater::DiagnosticStatusWrapper started = imuStatusAfter(statistics, 201, 0.005);
  EXPECT_EQ(valueOf(started, "gravity in the odometry frame (m/s^2)"), "0, -0.5, -9.79");
  EXPECT_EQ(valueOf(started, "accelerometer bias (m/s^2)"), "0.05, 0, -0.02");
  // The gate's intervals are counted, not warned of: the prior is the LiDAR's over them, as designed.
  EXPECT_EQ(valueOf(started, "accelerometer intervals gated"), "3");
  // The hold's turns are counted, not warned of: a drift past imu.tilt_hold_deg, corrected.
  EXPECT_EQ(valueOf(started, "tilt against gravity (deg)"), "0.25");
  EXPECT_EQ(valueOf(started, "scans held to gravity"), "4");
  EXPECT_EQ(started.level, diagnostic_msgs::DiagnosticStatus::OK) << started.message;
  EXPECT_EQ(valueOf(steady, "scans on the LiDAR-only prior"), "0");

  const diagnostic_updater::DiagnosticStatusWrapper silent = imuStatusAfter(statistics, 0, 0.005);
  EXPECT_EQ(silent.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(silent.message.find("IMU silent"), std::string::npos) << silent.message;

  // A bag played at half speed: 100 messages a second of wall time, 200 Hz by their stamps.
  EXPECT_EQ(imuStatusAfter(statistics, 101, 0.005, 2.0).level, diagnostic_msgs::DiagnosticStatus::OK);
  const diagnostic_updater::DiagnosticStatusWrapper slow = imuStatusAfter(statistics, 21, 0.05, 3.0);
  EXPECT_EQ(slow.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(slow.message.find("IMU rate 20 Hz under imu.min_rate_hz (50)"), std::string::npos) << slow.message;

  core.fallbacks[elo::imu_issue::kGap] = 2;
  core.dropped[elo::imu_issue::kNotFinite] = 1;
  statistics.update(core);
  statistics.messageUnused("no IMU -> LiDAR transform from TF");
  const diagnostic_updater::DiagnosticStatusWrapper faults = imuStatusAfter(statistics, 201, 0.005, 5.0);
  EXPECT_EQ(faults.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(faults.message.find("1 Imu messages unused, 1 IMU samples dropped, 2 scans on the LiDAR-only prior"),
            std::string::npos)
      << faults.message;
  EXPECT_EQ(valueOf(faults, std::string("scans on the LiDAR-only prior: ") + elo::imu_issue::kGap), "2");
  EXPECT_EQ(valueOf(faults, std::string("IMU samples dropped: ") + elo::imu_issue::kNotFinite), "1");
  EXPECT_EQ(valueOf(faults, "Imu messages unused: no IMU -> LiDAR transform from TF"), "1");
  EXPECT_EQ(valueOf(faults, "scans on the LiDAR-only prior"), "2");
  // The counts stay; a window without new ones is OK again.
  const diagnostic_updater::DiagnosticStatusWrapper again = imuStatusAfter(statistics, 201, 0.005, 7.0);
  EXPECT_EQ(again.level, diagnostic_msgs::DiagnosticStatus::OK) << again.message;
  EXPECT_EQ(valueOf(again, "scans on the LiDAR-only prior"), "2");
}
