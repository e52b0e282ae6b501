// elo_run --localize as a user runs it: a simulated drive written as a sequence, a map of its every
// other scan in the frame of its first (the frame elo_run --map writes), and the drive localized in it
// from the default initial pose and from a given one whose height comes from the map.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <string>

#include "../io/temp_directory.hpp"
#include "../tools/run_command.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/map_pcd.hpp"
#include "elo/sim/sequence_writer.hpp"
#include "shared_world.hpp"

namespace elo::test {
namespace {

constexpr int kFrames = 40;
constexpr float kMapStartsAhead = 2.0f;  // m, along the first scan's x axis

class LocalizeCli : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    directory_ = std::make_unique<TempDirectory>();
    sim::SimulationSpec spec;
    spec.world = sim::WorldFamily::urban;
    spec.trajectory = sim::TrajectoryKind::curves;
    spec.frames = kFrames;
    spec.seed = 5;
    const sim::Simulation simulation(spec);
    sim::writeSequence(simulation, directory_->file("sequence"));
    const Eigen::Isometry3d first_inverse = simulation.sensorPose(0).inverse();
    const MapCloud map = mapOfScans(
        [&](int frame) {
          return std::make_pair(simulation.scan(frame).cloud, first_inverse * simulation.sensorPose(frame));
        },
        kFrames, 2, 0.2, spec.config.localization.normal_radius);
    MapCloud without_normals = map;
    without_normals.normals.clear();
    // A point without coordinates, which loading skips and reports once.
    without_normals.points.push_back(Vec3f::Constant(std::numeric_limits<float>::quiet_NaN()));
    if (!without_normals.intensity.empty()) without_normals.intensity.push_back(0.0f);
    writeMapPcd(directory_->file("map.pcd"), without_normals);
    // The map of a drive that began further along the road (the map's frame is the first scan's).
    writeMapPcd(directory_->file("map_ahead.pcd"), mapAheadOf(map, Eigen::Isometry3d::Identity(), kMapStartsAhead));
  }
  static void TearDownTestSuite() { directory_.reset(); }

  // Runs elo_run --localize in `map` with `extra` options; the poses it wrote.
  static std::vector<Eigen::Isometry3d> localize(const std::string& extra, CommandResult& result,
                                                 const std::string& map = "map.pcd") {
    const std::string poses = directory_->file("poses.txt");
    result = runCommand(std::string(ELO_RUN_TOOL) + " --quiet --input " + directory_->file("sequence") + " --output " +
                        poses + " --localize " + directory_->file(map) + " --threads 2 " + extra);
    return result.exit_code == 0 ? readKittiPoses(poses) : std::vector<Eigen::Isometry3d>{};
  }
  static double worstError(const std::vector<Eigen::Isometry3d>& poses, size_t from) {
    const std::vector<Eigen::Isometry3d> truth = readKittiPoses(directory_->file("sequence/poses.txt"));
    double worst = 0.0;
    for (size_t i = from; i < poses.size(); ++i) {
      worst = std::max(worst, (poses[i].translation() - truth[i].translation()).norm());
    }
    return worst;
  }

  // Prints the lines of `output` that begin with one of `prefixes`.
  static void printLines(const std::string& output, std::initializer_list<const char*> prefixes) {
    for (size_t start = 0, end; (end = output.find('\n', start)) != std::string::npos; start = end + 1) {
      const std::string line = output.substr(start, end - start);
      for (const char* prefix : prefixes) {
        if (line.rfind(prefix, 0) == 0) {
          std::printf("%s\n", line.c_str());
          break;
        }
      }
    }
  }

  static std::unique_ptr<TempDirectory> directory_;
};
std::unique_ptr<TempDirectory> LocalizeCli::directory_;

TEST_F(LocalizeCli, LocalizesFromTheMapOriginByDefault) {
  CommandResult result;
  const std::vector<Eigen::Isometry3d> poses = localize("", result);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  ASSERT_EQ(poses.size(), static_cast<size_t>(kFrames));
  EXPECT_NE(result.output.find("normals estimated"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find(", 1 non-finite dropped,"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("localization: "), std::string::npos) << result.output;
  EXPECT_LT(worstError(poses, 0), 0.1) << result.output;
  printLines(result.output, {"localization:", "FPS"});  // the summary's figures, for the record
}

TEST_F(LocalizeCli, TakesAnInitialPoseWithTheHeightFromTheMap) {
  CommandResult result;
  const std::vector<Eigen::Isometry3d> poses = localize("--initial-pose '1.2 -0.8 nan 6'", result);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_LT(worstError(poses, 0), 0.1) << result.output;
}

// The drive begins short of the mapped road: the search from the default pose is refused, searched again as
// the odometry carries it, and taken once the vehicle is on the mapped road. The poses written before that
// match are placed in the map by it: the whole output is in the map frame.
TEST_F(LocalizeCli, PlacesTheScansBeforeTheFirstMatchInTheMap) {
  CommandResult result;
  const std::vector<Eigen::Isometry3d> poses = localize("", result, "map_ahead.pcd");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  ASSERT_EQ(poses.size(), static_cast<size_t>(kFrames));
  EXPECT_NE(result.output.find("scan 0: localization waiting for an initial pose: no pose around the hint fits"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("before the first accepted match were placed in the map by it"), std::string::npos)
      << result.output;
  EXPECT_LT(worstError(poses, 0), 0.1) << result.output;
  std::printf("map starting %.0f m ahead: worst position error over all %d scans %.3f m\n", kMapStartsAhead, kFrames,
              worstError(poses, 0));
  printLines(result.output, {"scan ", "localization:"});
}

// A hint where the map has nothing: never taken, and the output says its poses are not the map's.
TEST_F(LocalizeCli, SaysWhenNoPoseInTheMapWasFound) {
  CommandResult result;
  const std::vector<Eigen::Isometry3d> poses = localize("--initial-pose '500 500 0 0'", result);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(poses.size(), static_cast<size_t>(kFrames));
  EXPECT_NE(result.output.find("no map around the hint"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("no pose in the map was found: the 40 poses written while waiting"), std::string::npos)
      << result.output;
}

TEST_F(LocalizeCli, RejectsAMalformedInitialPoseAndAMissingMap) {
  CommandResult result;
  localize("--initial-pose '1 2 3'", result);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("--initial-pose expects"), std::string::npos) << result.output;
  result = runCommand(std::string(ELO_RUN_TOOL) + " --input " + directory_->file("sequence") + " --output " +
                      directory_->file("p.txt") + " --localize " + directory_->file("no_such_map.pcd"));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("no_such_map.pcd"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace elo::test
