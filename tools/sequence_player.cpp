// sequence_player: publishes a sequence on disk as sensor_msgs/PointCloud2 at the sequence's own rate, as
// a driver would, looping for as many scans as asked. Each pass's stamps continue the previous pass's,
// so a sequence of one closed lap (elo_sim --trajectory loop) plays as one endless drive: the soak test
// (tools/soak.sh) drives the nodelet for hours without a bag of that size on disk. Thin: the scans are
// read by elo::Sequence and packed by the ROS layer's toPointCloud2, as kitti_to_bag does.
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "cloud_conversion.hpp"
#include "command_line.hpp"
#include "elo/io/sequence.hpp"

namespace {

constexpr char kUsage[] = R"(usage: sequence_player --input DIR [options]

Publishes the scans of DIR (KITTI layout: DIR/velodyne/*.bin with optional times.txt; elo_sim output;
or a directory of .pcd / .bin scans) as sensor_msgs/PointCloud2 (x y z intensity float32, ring uint16
and time float32 when the scans have them) at the sequence's timestamps, paced by the wall clock.
After the last scan it starts again, every stamp shifted by the sequence's duration (its span plus
one scan period), so stamps keep increasing at the sequence's rate. ROS_MASTER_URI says which master.

options:
  --topic NAME          cloud topic (default /points)
  --frame NAME          the clouds' frame_id (default velodyne)
  --scans N             scans to publish in all, looping over the sequence (default: the sequence once)
  --rate R              playback speed factor (default 1: the sequence's own rate)
  --start-time S        stamp of the first scan in seconds (default: the wall clock when playing starts)
  --subscribers N       subscribers to wait for before the first scan, 60 s at most (default 1)
  --progress K          print a line every K scans (default 1000; 0: never)
  --help
)";

using elo::tools::UsageError;

struct Options {
  std::string input;
  std::string topic = "/points";
  std::string frame = "velodyne";
  size_t scans = 0;  // 0: the sequence once
  double rate = 1.0;
  double start_time = -1.0;  // negative: the wall clock
  int subscribers = 1;
  size_t progress = 1000;
};

Options parseArguments(int argc, char** argv) {
  Options options;
  elo::tools::Arguments arguments(argc, argv);
  while (arguments.next()) {
    const std::string& flag = arguments.flag();
    if (flag == "--input") {
      options.input = arguments.value();
    } else if (flag == "--topic") {
      options.topic = arguments.value();
    } else if (flag == "--frame") {
      options.frame = arguments.value();
    } else if (flag == "--scans") {
      options.scans = arguments.number<size_t>();
    } else if (flag == "--rate") {
      options.rate = arguments.number<double>();
      if (!(options.rate > 0.0)) throw UsageError("--rate must be positive");
    } else if (flag == "--start-time") {
      options.start_time = arguments.number<double>();
      if (!(options.start_time > 0.0)) throw UsageError("--start-time must be positive: ROS reads 0 as 'no time'");
    } else if (flag == "--subscribers") {
      options.subscribers = arguments.number<int>();
    } else if (flag == "--progress") {
      options.progress = arguments.number<size_t>();
    } else {
      arguments.rejectFlag();
    }
  }
  if (options.input.empty()) throw UsageError("--input is required");
  return options;
}

// Where scan `index` of the looped playback falls in the sequence, and its stamp there.
class LoopedTimeline {
 public:
  explicit LoopedTimeline(const elo::Sequence& sequence) : sequence_(sequence) {
    const size_t size = sequence.size();
    const double span = sequence.stamp(size - 1) - sequence.stamp(0);
    // One scan period past the last scan: the next pass starts where a next scan would have been.
    const double period = size > 1 ? span / static_cast<double>(size - 1) : 0.1;
    duration_ = span + period;
  }

  size_t scanOf(size_t index) const { return index % sequence_.size(); }
  // Seconds from the first scan of the playback.
  double offsetOf(size_t index) const {
    const size_t pass = index / sequence_.size();
    return static_cast<double>(pass) * duration_ + sequence_.stamp(scanOf(index)) - sequence_.stamp(0);
  }

 private:
  const elo::Sequence& sequence_;
  double duration_ = 0.0;
};

constexpr double kSubscriberTimeout = 60.0;  // s

void waitForSubscribers(const ros::Publisher& publisher, int count) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kSubscriberTimeout);
  while (ros::ok() && publisher.getNumSubscribers() < static_cast<uint32_t>(count)) {
    if (ros::WallTime::now() > deadline) {
      throw std::runtime_error(std::to_string(publisher.getNumSubscribers()) + " of " + std::to_string(count) +
                               " subscribers on " + publisher.getTopic() + " after " +
                               std::to_string(static_cast<int>(kSubscriberTimeout)) + " s");
    }
    ros::WallDuration(0.05).sleep();
  }
}

int play(const Options& options) {
  const elo::Sequence sequence(options.input);
  const LoopedTimeline timeline(sequence);
  const size_t total = options.scans > 0 ? options.scans : sequence.size();
  ros::NodeHandle node;
  // Deep enough that a subscriber busy for a second loses nothing in transport: every scan must reach
  // the odometry, which counts whatever it then drops.
  ros::Publisher publisher = node.advertise<sensor_msgs::PointCloud2>(options.topic, 100);
  waitForSubscribers(publisher, options.subscribers);

  const ros::WallTime wall_start = ros::WallTime::now();
  const double stamp_start = options.start_time > 0.0 ? options.start_time : wall_start.toSec();
  double latest_ms = 0.0;  // the latest any scan went out after its time
  size_t late = 0;         // scans published more than one millisecond after their time
  for (size_t index = 0; index < total && ros::ok(); ++index) {
    elo::PointCloud cloud = sequence.load(timeline.scanOf(index));
    cloud.stamp = stamp_start + timeline.offsetOf(index);
    const sensor_msgs::PointCloud2 message = elo_ros::toPointCloud2(cloud, options.frame);
    const ros::WallTime due = wall_start + ros::WallDuration(timeline.offsetOf(index) / options.rate);
    const double lateness_ms = (ros::WallTime::now() - due).toSec() * 1000.0;
    if (lateness_ms < 0.0) (due - ros::WallTime::now()).sleep();
    if (lateness_ms > 1.0) ++late;
    latest_ms = std::max(latest_ms, lateness_ms);
    publisher.publish(message);
    if (options.progress > 0 && (index + 1) % options.progress == 0) {
      std::printf("published %zu of %zu scans\n", index + 1, total);
      std::fflush(stdout);
    }
  }
  std::printf("published %zu scans of %s (%zu a pass) on %s at %gx; %zu went out more than 1 ms late "
              "(latest %.1f ms)\n",
              total, options.input.c_str(), sequence.size(), publisher.getTopic().c_str(), options.rate, late,
              std::max(latest_ms, 0.0));
  // Lets the transport hand over the last scans before the publisher goes away.
  ros::WallDuration(1.0).sleep();
  return ros::ok() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return elo::tools::runTool("sequence_player", kUsage, argc, argv, [&] {
    const Options options = parseArguments(argc, argv);
    ros::init(argc, argv, "sequence_player", ros::init_options::AnonymousName);
    return play(options);
  });
}
