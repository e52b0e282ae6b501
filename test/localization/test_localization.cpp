// Localization on a saved map (issue 28), on simulated drives with exact ground truth: a map made of one
// drive of a world, other drives of the same world localized in it (another lane, a later start, other
// noise and sensor unit, another sensor model), from an initial pose off by metres, and a kidnapped
// vehicle. ELO_LOCALIZATION_LONG builds the long gates (over a kilometre) instead of the short ones.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

#include "core/map/map_residency.hpp"
#include "elo/localization/localizer.hpp"
#include "elo/sim/sensors.hpp"
#include "shared_world.hpp"

namespace elo::test {
namespace {

#ifdef ELO_LOCALIZATION_LONG
constexpr double kDriveSeconds = 130.0;  // about 1.2 km of the urban route
constexpr int kMaxFrames = 100000;
#else
constexpr double kDriveSeconds = 12.0;   // the map's drive
constexpr int kMaxFrames = 50;           // scans localized
#endif
constexpr double kMapVoxel = 0.2;          // m
constexpr int kConvergedWithin = 20;       // scans

Config sensorConfig(const std::string& sensor) {
  Config config;
  sim::loadSensor(sensor, config);
  return config;
}

// The urban world of every gate, and the map of its first drive (HDL-64E, centre lane).
class Localization : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = std::make_unique<SharedWorld>(sim::WorldFamily::urban, sim::TrajectoryKind::curves, kDriveSeconds + 6.0, 7);
    const Drive mapping(*world_, sensorConfig("hdl64"), DrivePlan{0.0, 0.0, 11, 1});
    const Config config = sensorConfig("hdl64");
    map_ = std::make_shared<MapCloud>(
        mapOfDrive(mapping, mapping.frameCount(), 2, kMapVoxel, config.localization.normal_radius));
  }
  static void TearDownTestSuite() {
    map_.reset();
    world_.reset();
  }

  static std::unique_ptr<SharedWorld> world_;
  static std::shared_ptr<MapCloud> map_;
};
std::unique_ptr<SharedWorld> Localization::world_;
std::shared_ptr<MapCloud> Localization::map_;

// A drive of another lane, starting later, with other noise and another unit of the sensor.
DrivePlan otherDrive() { return DrivePlan{3.0, 1.2, 23, 2}; }

Eigen::Isometry3d offsetBy(const Eigen::Isometry3d& pose, double metres, double yaw_deg) {
  const Eigen::Vector3d shift(metres * std::cos(0.7), metres * std::sin(0.7), 0.0);
  return pose * Eigen::Translation3d(shift) * Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ());
}

struct Localized {
  std::vector<double> errors;  // position error per scan (m), NaN while not localized
  std::vector<LocalizationResult> results;
  std::vector<double> odometry_milliseconds;  // FrameResult::times.total
  double rmse_after(int first) const {
    double sum = 0.0;
    int count = 0;
    for (size_t i = static_cast<size_t>(first); i < errors.size(); ++i) {
      sum += errors[i] * errors[i];
      ++count;
    }
    return count > 0 ? std::sqrt(sum / count) : INFINITY;
  }
};

// Localizes `frames` scans of `drive` from `hint` (for scan 0), `sensor`'s own config.
Localized localize(const Drive& drive, const std::string& sensor, std::shared_ptr<MapCloud> map,
                   const Eigen::Isometry3d& hint, int frames) {
  Config config = sensorConfig(sensor);
  Odometry odometry(config);
  Localizer localizer(odometry, map);
  localizer.setInitialPose(hint);
  Localized localized;
  for (int frame = 0; frame < frames; ++frame) {
    const FrameResult odometry_result = odometry.process(drive.scan(frame));
    const LocalizationResult result = localizer.update(odometry_result);
    const bool localized_now = result.state != LocalizationState::waiting_for_pose;
    localized.errors.push_back(localized_now ? (result.pose.translation() - drive.pose(frame).translation()).norm() : NAN);
    localized.results.push_back(result);
    localized.odometry_milliseconds.push_back(odometry_result.times.total);
  }
  return localized;
}

int framesOf(const Drive& drive) { return std::min(drive.frameCount(), kMaxFrames); }

// Mean and largest time of the localization on the scans that ran no search (ms), and of the searches.
void printTimes(const Localized& run, const char* name) {
  double tracking = 0.0;
  double odometry = 0.0;
  double rendering = 0.0;
  size_t rendered = 0;
  double worst = 0.0;
  double searching = 0.0;
  int tracked = 0;
  int searches = 0;
  for (size_t i = 0; i < run.results.size(); ++i) {
    const LocalizationResult& result = run.results[i];
    if (result.searched) {
      searching += result.milliseconds;
      ++searches;
    } else {
      tracking += result.milliseconds;
      odometry += run.odometry_milliseconds[i];
      rendering += result.render_milliseconds;
      rendered += result.map_points_rendered;
      worst = std::max(worst, result.milliseconds);
      ++tracked;
    }
  }
  tracked = std::max(tracked, 1);
  std::printf("%s: localization %.1f ms a scan (largest %.1f; rendering %zu map points %.1f) on top of the odometry's "
              "%.1f ms, %.0f ms a search\n",
              name, tracking / tracked, worst, rendered / tracked, rendering / tracked, odometry / tracked,
              searches > 0 ? searching / searches : 0.0);
}

TEST_F(Localization, Hdl64ConvergesFromTwoMetresAndTenDegreesOffAndTracks) {
  const Drive drive(*world_, sensorConfig("hdl64"), otherDrive());
  const Localized run = localize(drive, "hdl64", map_, offsetBy(drive.pose(0), 2.0, 10.0), framesOf(drive));
  ASSERT_TRUE(run.results.front().searched);
  int converged = -1;
  for (size_t i = 0; i < run.errors.size() && converged < 0; ++i) {
    if (run.results[i].matched && run.errors[i] < 0.1) converged = static_cast<int>(i);
  }
  ASSERT_GE(converged, 0) << "never converged";
  EXPECT_LT(converged, kConvergedWithin);
  size_t matched = 0;
  for (const auto& result : run.results) matched += result.matched ? 1 : 0;
  const double rmse = run.rmse_after(kConvergedWithin);
  std::printf("HDL-64E in the HDL-64E map: converged at scan %d, position RMSE %.3f m over %zu scans, %zu matched\n",
              converged, rmse, run.errors.size(), matched);
  printTimes(run, "HDL-64E");
  EXPECT_LE(rmse, 0.10);
  EXPECT_GT(matched, run.results.size() * 9 / 10);
}

// Another sensor model in the HDL-64E's map, its scans distorted by the motion (per-point times).
TEST_F(Localization, Vlp16LocalizesInTheHdl64Map) {
  sim::LidarOptions distorted;
  distorted.deskewed = false;
  const Drive drive(*world_, sensorConfig("vlp16"), otherDrive(), distorted);
  const Localized run = localize(drive, "vlp16", map_, offsetBy(drive.pose(0), 1.0, 5.0), framesOf(drive));
  const double rmse = run.rmse_after(kConvergedWithin);
  size_t matched = 0;
  for (const auto& result : run.results) matched += result.matched ? 1 : 0;
  std::printf("VLP-16 in the HDL-64E map: position RMSE %.3f m over %zu scans, %zu matched\n", rmse,
              run.errors.size(), matched);
  printTimes(run, "VLP-16");
  EXPECT_LE(rmse, 0.20);
  EXPECT_GT(matched, run.results.size() * 3 / 4);
}

// A hint far outside the search is refused, and searched around again every lost_after scans as the
// odometry carries it: the pose never jumps to a bad match.
TEST_F(Localization, AWrongHintIsNeverAccepted) {
  const Drive drive(*world_, sensorConfig("hdl64"), otherDrive());
  Odometry odometry(sensorConfig("hdl64"));
  const int lost_after = odometry.config().localization.lost_after;
  Localizer localizer(odometry, map_);
  localizer.setInitialPose(offsetBy(drive.pose(0), 25.0, 0.0));
  int searches = 0;
  for (int frame = 0; frame <= 3 * lost_after; ++frame) {
    const LocalizationResult result = localizer.update(odometry.process(drive.scan(frame)));
    EXPECT_EQ(result.searched, frame % lost_after == 0) << "scan " << frame;
    searches += result.searched ? 1 : 0;
    EXPECT_FALSE(result.matched) << "scan " << frame << ": inlier share " << result.health.inlier_share << ", RMS "
                                 << result.health.rms;
    EXPECT_EQ(result.state, LocalizationState::waiting_for_pose);
    EXPECT_TRUE(result.hint_carried);
  }
  EXPECT_EQ(searches, 4);
}

// A drive that begins short of the mapped road, given its true pose at the first scan (as from GPS): the
// search there is refused, the scan seeing mostly what the map lacks, and the hint is not dropped. The
// odometry carries it, through a restart of the odometry too (time going backwards), and the search
// around it runs every lost_after scans until, the vehicle on the mapped road, one is taken; from then
// on the drive tracks.
TEST_F(Localization, AHintGivenBeforeTheMappedRoadIsTakenOnReachingIt) {
  const Drive drive(*world_, sensorConfig("hdl64"), otherDrive());
  const auto ahead = std::make_shared<MapCloud>(mapAheadOf(*map_, drive.pose(0), 10.0));
  Odometry odometry(sensorConfig("hdl64"));
  const int lost_after = odometry.config().localization.lost_after;
  Localizer localizer(odometry, ahead);
  localizer.setInitialPose(drive.pose(0));
  constexpr int kRestartAt = 25;         // from this scan on the stamps are 5 s earlier: the odometry restarts
  constexpr int kFrames = 50;
  int taken = -1;
  std::vector<double> errors;
  for (int frame = 0; frame < std::min(framesOf(drive), kFrames); ++frame) {
    PointCloud scan = drive.scan(frame);
    if (frame >= kRestartAt) scan.stamp -= 5.0;
    const FrameResult odometry_result = odometry.process(scan);
    EXPECT_EQ(odometry_result.reset, frame == kRestartAt);
    const LocalizationResult result = localizer.update(odometry_result);
    const double error = (result.pose.translation() - drive.pose(frame).translation()).norm();
    if (taken < 0) {
      // Until one is taken, the search around the carried hint runs every lost_after scans.
      EXPECT_EQ(result.searched, frame % lost_after == 0) << "scan " << frame;
      if (result.searched && !result.matched) {
        EXPECT_NE(result.refusal.find("no pose around the hint fits"), std::string::npos) << result.refusal;
      }
      if (result.matched) {
        taken = frame;
        EXPECT_LT(error, 0.1) << "taken at scan " << frame;
      } else {
        EXPECT_EQ(result.state, LocalizationState::waiting_for_pose) << "scan " << frame;
        EXPECT_TRUE(result.hint_carried) << "scan " << frame;
        // The true first pose, carried by the odometry: where the vehicle is, but for the drift and, from
        // the restart on, the step the restart did not see (its scan is put where the one before was).
        const std::optional<PoseHint> carried = localizer.carriedHint();
        ASSERT_TRUE(carried.has_value()) << "scan " << frame;
        const double unseen_step = frame >= kRestartAt ? (drive.pose(kRestartAt).translation() -
                                                          drive.pose(kRestartAt - 1).translation()).norm()
                                                       : 0.0;
        EXPECT_LT((carried->map_from_sensor.translation() - drive.pose(frame).translation()).norm(), 0.1 + unseen_step)
            << "scan " << frame;
      }
      continue;
    }
    EXPECT_EQ(result.state, LocalizationState::tracking) << "scan " << frame;
    EXPECT_FALSE(result.hint_carried);
    EXPECT_FALSE(localizer.carriedHint().has_value());
    errors.push_back(error);
  }
  ASSERT_GT(taken, 0) << "the hint was never taken (the first search should be refused: the map starts 10 m ahead)";
  ASSERT_FALSE(errors.empty()) << "taken at the last scan";
  double sum = 0.0;
  for (double error : errors) sum += error * error;
  const double rmse = std::sqrt(sum / errors.size());
  std::printf("a hint given 10 m short of the map: taken at scan %d (searched every %d scans; the odometry restarted at "
              "scan %d), position RMSE %.3f m over the next %zu scans\n",
              taken, lost_after, kRestartAt, rmse, errors.size());
  EXPECT_LE(rmse, 0.10);
}

// The other drive (HDL-64E) localized from its true first pose over its first `scans` scans.
struct TrackedDrive {
  TrackedDrive(const SharedWorld& world, std::shared_ptr<MapCloud> map, int scans)
      : drive(world, sensorConfig("hdl64"), otherDrive()), odometry(sensorConfig("hdl64")), localizer(odometry, map) {
    localizer.setInitialPose(drive.pose(0));
    for (int frame = 0; frame < scans; ++frame) localizer.update(odometry.process(drive.scan(frame)));
  }
  Drive drive;
  Odometry odometry;
  Localizer localizer;
};

// Time goes backwards while tracking, on a scan the odometry then skips (ten points: too few), and the
// odometry restarts at the identity. The localizer puts the new frame where the last scan was, searches
// around it at the next scan and tracks on; the pose in the map does not jump.
TEST_F(Localization, AnOdometryRestartOnASkippedScanKeepsThePoseInTheMap) {
  constexpr int kRestartAt = 15;
  TrackedDrive tracked(*world_, map_, kRestartAt);
  ASSERT_EQ(tracked.localizer.state(), LocalizationState::tracking);
  const Drive& drive = tracked.drive;
  Odometry& odometry = tracked.odometry;
  Localizer& localizer = tracked.localizer;

  PointCloud ten_points = drive.scan(kRestartAt);
  ten_points.points.resize(10);
  ten_points.intensity.resize(std::min<size_t>(ten_points.intensity.size(), 10));
  ten_points.ring.resize(std::min<size_t>(ten_points.ring.size(), 10));
  ten_points.time.resize(std::min<size_t>(ten_points.time.size(), 10));
  ten_points.stamp -= 5.0;
  const FrameResult skipped = odometry.process(ten_points);
  ASSERT_TRUE(skipped.reset && !skipped.processed) << skipped.skip_reason;
  const LocalizationResult held = localizer.update(skipped);
  const double held_error = (held.pose.translation() - drive.pose(kRestartAt - 1).translation()).norm();
  EXPECT_LT(held_error, 0.1) << "the skipped scan keeps the last pose in the map";

  double worst = 0.0;
  for (int frame = kRestartAt + 1; frame < kRestartAt + 12; ++frame) {
    PointCloud scan = drive.scan(frame);
    scan.stamp -= 5.0;
    const LocalizationResult result = localizer.update(odometry.process(scan));
    EXPECT_EQ(result.searched, frame == kRestartAt + 1) << "scan " << frame;
    EXPECT_TRUE(result.matched) << "scan " << frame << ": " << result.refusal;
    worst = std::max(worst, (result.pose.translation() - drive.pose(frame).translation()).norm());
  }
  std::printf("time backwards on a skipped scan while tracking: the pose kept %.3f m from the last scan's truth; "
              "searched at the next scan, worst error over the next 11 scans %.3f m\n",
              held_error, worst);
  EXPECT_LT(worst, 0.1);
}

// The vehicle is carried 50 m along the road between two scans. The localizer refuses the matches at the
// old place, declares itself lost, and relocalizes from a hint 4 m and 25 degrees off the truth.
TEST_F(Localization, AKidnappedVehicleIsDetectedAndRelocalizedFromAHint) {
  constexpr int kBefore = 15;
  TrackedDrive tracked(*world_, map_, kBefore);
  ASSERT_EQ(tracked.localizer.state(), LocalizationState::tracking);
  const Drive& drive = tracked.drive;
  Odometry& odometry = tracked.odometry;
  Localizer& localizer = tracked.localizer;
  int landing = kBefore;
  while (landing < drive.frameCount() &&
         (drive.pose(landing).translation() - drive.pose(kBefore - 1).translation()).norm() < 50.0) {
    ++landing;
  }
  ASSERT_LT(landing + 20, drive.frameCount()) << "the drive is too short to land 50 m on";
  const int lost_after = odometry.config().localization.lost_after;
  int frame = landing;
  int detected = -1;
  for (; frame < landing + lost_after + 5 && detected < 0; ++frame) {
    const LocalizationResult result = localizer.update(odometry.process(drive.scan(frame)));
    const double error = (result.pose.translation() - drive.pose(frame).translation()).norm();
    if (result.matched) {
      EXPECT_LT(error, 0.5) << "scan " << frame << ": a match accepted far from the truth";
    }
    if (result.state == LocalizationState::lost) detected = frame - landing;
  }
  ASSERT_GE(detected, 0) << "the kidnapping went unnoticed";
  localizer.setInitialPose(offsetBy(drive.pose(frame), 4.0, 25.0), 5.0, 30.0);
  const LocalizationResult relocalized = localizer.update(odometry.process(drive.scan(frame)));
  EXPECT_TRUE(relocalized.searched);
  ASSERT_TRUE(relocalized.matched) << "inlier share " << relocalized.health.inlier_share << ", RMS "
                                   << relocalized.health.rms;
  double worst = 0.0;
  for (int after = frame + 1; after < std::min(frame + 20, drive.frameCount()); ++after) {
    const LocalizationResult result = localizer.update(odometry.process(drive.scan(after)));
    worst = std::max(worst, (result.pose.translation() - drive.pose(after).translation()).norm());
  }
  std::printf("kidnapped 50 m: detected after %d scans, relocalized in %.0f ms; worst error over the next 19 scans %.3f m\n",
              detected, relocalized.milliseconds, worst);
  EXPECT_LT(worst, 0.2);
}

// The part of the map the CUDA backend holds (MapResidency) along the other drive, rendered where each
// scan truly is, as a localized drive renders it: every render finds its points held, and over the long
// drive the device holds a part of the map bounded by the render's reach, not the map.
TEST_F(Localization, AGpuHoldsOnlyThePartOfTheMapNearTheDrive) {
  const Drive drive(*world_, sensorConfig("hdl64"), otherDrive());
  const Config config = sensorConfig("hdl64");
  const MapTiles tiles(*map_, config.localization.tile_size);
  MapResidency residency(*map_, config.localization.tile_size);
  int sets = 0;
  double choosing = 0.0;  // ms, on the host
  size_t most_held = 0;
  std::vector<int32_t> drawn;
  std::vector<int32_t> places;
  for (int frame = 0; frame < drive.frameCount(); ++frame) {
    drawn.clear();
    tiles.pointsNear(drive.pose(frame).translation(), config.localization.render_range, drawn);
    places.resize(drawn.size());
    if (residency.locate(drawn, places.data())) continue;
    const auto start = std::chrono::steady_clock::now();
    residency.holdAround(drawn);
    choosing += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ++sets;
    most_held = std::max(most_held, residency.held().size());
    ASSERT_TRUE(residency.locate(drawn, places.data())) << "scan " << frame;
    for (size_t i = 0; i < drawn.size(); ++i) ASSERT_EQ(residency.held()[places[i]], drawn[i]) << "scan " << frame;
  }
  std::printf("the GPU's part of the map over %d scans: %d sets (%.1f ms each to choose), at most %zu of the map's "
              "%zu points (%.0f %%)\n",
              drive.frameCount(), sets, choosing / std::max(sets, 1), most_held, map_->size(),
              100.0 * most_held / map_->size());
  EXPECT_GE(sets, 1);
#ifdef ELO_LOCALIZATION_LONG
  EXPECT_LT(most_held, map_->size() / 3);
#endif
}

#ifndef ELO_LOCALIZATION_LONG
// A tunnel, mapped by one drive and searched from another's scans. On the open approach the search from
// a hint 2 m and 10 degrees off is taken; 100 m inside, where nothing varies along the axis, the winner
// is any pose along it (the candidates converge metres apart with the same fit), and the search is
// refused, from the true pose too: by the degeneracy of the map match, and, with that analysis off, by
// the rival candidates that fit as well. The pose never jumps along the tunnel.
TEST(LocalizationInATunnel, ASearchIsRefusedWhereTheMapLeavesTheAxisFree) {
  const SharedWorld world(sim::WorldFamily::tunnel, sim::TrajectoryKind::straight, 22.0, 3);
  const Config mapping_config = sensorConfig("hdl64");
  const Drive mapping(world, mapping_config, DrivePlan{0.0, 0.0, 11, 1});
  const auto map = std::make_shared<MapCloud>(mapOfDrive(mapping, mapping.frameCount(), 2, kMapVoxel,
                                                         mapping_config.localization.normal_radius));
  const Drive drive(world, mapping_config, DrivePlan{1.0, 0.8, 23, 2});
  const auto firstFrameBeyond = [&drive](double x) {
    int frame = 0;
    while (frame < drive.frameCount() && drive.pose(frame).translation().x() < x) ++frame;
    return frame;
  };
  // The first scan searched from `hint`, with the degeneracy analysis at `threshold`.
  const auto searchedFrom = [&](int frame, const Eigen::Isometry3d& hint, double threshold) {
    Config config = sensorConfig("hdl64");
    config.registration.degeneracy_threshold = threshold;
    Odometry odometry(config);
    Localizer localizer(odometry, map);
    localizer.setInitialPose(hint);
    return localizer.update(odometry.process(drive.scan(frame)));
  };
  const double threshold = mapping_config.registration.degeneracy_threshold;

  const int approach = firstFrameBeyond(30.0);
  const LocalizationResult outside = searchedFrom(approach, offsetBy(drive.pose(approach), 2.0, 10.0), threshold);
  ASSERT_TRUE(outside.matched) << outside.refusal;
  EXPECT_LT((outside.pose.translation() - drive.pose(approach).translation()).norm(), 0.1);

  const int inside = firstFrameBeyond(200.0);
  ASSERT_LT(inside, drive.frameCount());
  for (const double along : {0.0, 2.0}) {
    const Eigen::Isometry3d hint = drive.pose(inside) * Eigen::Translation3d(along, 0.0, 0.0);
    const LocalizationResult degenerate = searchedFrom(inside, hint, threshold);
    EXPECT_FALSE(degenerate.matched) << "hint " << along << " m along: error "
                                     << (degenerate.pose.translation() - drive.pose(inside).translation()).norm();
    EXPECT_NE(degenerate.refusal.find("does not fix the pose along x"), std::string::npos) << degenerate.refusal;
    EXPECT_EQ(degenerate.state, LocalizationState::waiting_for_pose);

    const LocalizationResult rivalled = searchedFrom(inside, hint, 0.0);
    EXPECT_FALSE(rivalled.matched) << "hint " << along << " m along, no degeneracy analysis";
    EXPECT_NE(rivalled.refusal.find("fits the map about as well"), std::string::npos) << rivalled.refusal;
  }
}
#endif

}  // namespace
}  // namespace elo::test
