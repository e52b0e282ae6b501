// kitti_to_bag: writes a sequence on disk (KITTI layout, elo_sim output, or a directory of PCD scans) as
// a ROS bag of sensor_msgs/PointCloud2 at the sequence's timestamps, with the ground truth as
// nav_msgs/Odometry and TF when the sequence has poses. Thin: parse flags, load scans, write messages.
#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "command_line.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/sequence.hpp"
#include "sequence_bag.hpp"

namespace {

constexpr char kUsage[] = R"(usage: kitti_to_bag --input DIR --output BAG [options]

Writes the scans of DIR (KITTI layout: DIR/velodyne/*.bin with optional times.txt, poses.txt and
calib.txt; elo_sim output; or a directory of .pcd / .bin scans) to BAG as sensor_msgs/PointCloud2
(x y z intensity float32, ring uint16 and time float32 when the scans have them), each stamped and
recorded at its scan time plus --start-time. With DIR/poses.txt the ground truth goes to
/ground_truth (nav_msgs/Odometry) and /tf, as the sensor's pose in the frame of the first scan.

options:
  --topic NAME          cloud topic (default /points)
  --frame NAME          the clouds' frame_id (default velodyne)
  --frames N            write only the first N scans
  --start-time S        seconds added to every scan time (default 1: ROS reads time 0 as 'no time')
  --poses-frame camera|lidar
                        the frame poses.txt is written in: camera for KITTI odometry (converted to
                        the LiDAR frame with calib.txt), lidar for elo_sim. Required when DIR has
                        both poses.txt and calib.txt, since both tools write both files.
  --gt-frame NAME       parent frame of the ground truth (default odom: the frame the odometry starts
                        in when it publishes the sensor frame directly)
  --gt-child-frame NAME child frame of the ground truth (default <frame>_ground_truth)
  --help
)";

struct Options {
  std::string input;
  std::string output;
  size_t max_frames = 0;  // 0: every scan
  std::optional<std::string> poses_frame;
  elo_ros::SequenceBagOptions bag;
};

using elo::tools::UsageError;

Options parseArguments(int argc, char** argv) {
  Options options;
  elo::tools::Arguments arguments(argc, argv);
  while (arguments.next()) {
    const std::string& flag = arguments.flag();
    const auto value = [&] { return arguments.value(); };
    if (flag == "--input") {
      options.input = value();
    } else if (flag == "--output") {
      options.output = value();
    } else if (flag == "--topic") {
      options.bag.topic = value();
    } else if (flag == "--frame") {
      options.bag.frame = value();
    } else if (flag == "--frames") {
      options.max_frames = arguments.number<size_t>();
    } else if (flag == "--start-time") {
      options.bag.start_time = arguments.number<double>();
    } else if (flag == "--poses-frame") {
      options.poses_frame = value();
      if (*options.poses_frame != "camera" && *options.poses_frame != "lidar") {
        throw UsageError("--poses-frame must be camera or lidar, got '" + *options.poses_frame + "'");
      }
    } else if (flag == "--gt-frame") {
      options.bag.gt_frame = value();
    } else if (flag == "--gt-child-frame") {
      options.bag.gt_child_frame = value();
    } else {
      arguments.rejectFlag();
    }
  }
  if (options.input.empty() || options.output.empty()) throw UsageError("--input and --output are required");
  return options;
}

// The sensor's ground-truth poses in the frame of the first scan, or none when DIR has no poses.txt.
std::vector<Eigen::Isometry3d> sensorGroundTruth(const elo::Sequence& sequence, const Options& options) {
  if (!sequence.hasGroundTruth()) return {};
  std::string frame = options.poses_frame.value_or(sequence.hasCalibration() ? "" : "lidar");
  if (frame.empty()) {
    throw UsageError("'" + sequence.directory() +
                     "' has poses.txt and calib.txt: say --poses-frame camera (KITTI odometry) or lidar (elo_sim)");
  }
  if (frame == "lidar") return sequence.groundTruth();
  if (!sequence.hasCalibration()) throw UsageError("--poses-frame camera needs calib.txt in '" + sequence.directory() + "'");
  return elo::cameraToLidar(sequence.groundTruth(), sequence.calibration());
}

int run(const Options& options) {
  const elo::Sequence sequence(options.input);
  const size_t scans = options.max_frames > 0 ? std::min(options.max_frames, sequence.size()) : sequence.size();
  const std::vector<Eigen::Isometry3d> ground_truth = sensorGroundTruth(sequence, options);
  elo_ros::SequenceBagWriter bag(options.output, options.bag);
  for (size_t i = 0; i < scans; ++i) {
    if (ground_truth.empty()) {
      bag.write(sequence.load(i));
    } else {
      bag.write(sequence.load(i), ground_truth[i]);
    }
  }
  bag.close();
  std::printf("wrote %zu scans (%zu points) on %s%s to %s\n", bag.scans(), bag.points(), options.bag.topic.c_str(),
              ground_truth.empty() ? "" : ", with ground truth on /ground_truth and /tf", options.output.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return elo::tools::runTool("kitti_to_bag", kUsage, argc, argv, [&] { return run(parseArguments(argc, argv)); });
}
