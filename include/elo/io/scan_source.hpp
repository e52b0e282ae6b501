// Where a run's scans come from: a sequence directory (elo::Sequence), a ROS 2 bag (elo::Ros2Bag) or a
// ROS 1 bag (the ROS layer's Ros1Bag). Each knows how many scans it holds and their stamps once opened,
// so that a run can choose the scans it plays (playOrder) before reading any, and reads one scan at a
// time, so that a long drive never sits in memory.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

#include "elo/config.hpp"
#include "elo/io/io_error.hpp"
#include "elo/types.hpp"

namespace elo {

// A scan that was read, with what the reader noticed on the way.
struct LoadedScan {
  PointCloud cloud;
  size_t non_finite_points = 0;  // points dropped for a NaN or infinite coordinate
  std::string warning;           // e.g. a per-point time field that could not be read; empty when none
};

// A scan that cannot be used: `reason` is the short form a run counts skips by ("scan file unreadable",
// "message unreadable", "truncated data", ...); what() says in full what is wrong and where.
class UnusableScan : public IoError {
 public:
  UnusableScan(std::string reason, const std::string& detail) : IoError(detail), reason_(std::move(reason)) {}
  const std::string& reason() const { return reason_; }

 private:
  std::string reason_;
};

class ScanSource {
 public:
  virtual ~ScanSource() = default;

  virtual size_t size() const = 0;
  // The stamp of scan `index` (s), known without reading the scan; scans are in stamp order.
  virtual double stamp(size_t index) const = 0;
  // Throws UnusableScan when the scan cannot be read or used.
  virtual LoadedScan read(size_t index) const = 0;
  // What a user would call it in a message: "bag 'drive.bag', topic /points".
  virtual std::string describe() const = 0;
  // What the source noticed when it was opened and a run should say (a damaged file read up to the
  // damage); empty when nothing.
  virtual std::string warning() const { return ""; }

  // The velodyne->camera transform that KITTI sequences carry (calib.txt); a bag has none.
  virtual bool hasCalibration() const { return false; }
  // Throws IoError when there is none.
  virtual const Eigen::Isometry3d& calibration() const { throw IoError(describe() + " has no camera calibration"); }
};

// A topic of a bag: its name, message type and message count.
struct BagTopic {
  std::string name;
  std::string type;
  size_t messages = 0;
};

// The topic a bag's clouds are read from: `requested` when given (it must be a topic of `cloud_type`),
// else the bag's only topic of `cloud_type`. Throws IoError listing the candidates when there is none or
// more than one, and the bag's topics when `requested` is not a cloud topic.
std::string chooseCloudTopic(const std::string& bag, const std::vector<BagTopic>& topics, const std::string& cloud_type,
                             const std::string& requested);

// The topic a bag's Imu messages are read from: `requested` when given (it must be a topic of `imu_type`),
// else the bag's only topic of `imu_type`; empty when it has none. Throws IoError listing the bag's topics
// when `requested` is not an Imu topic, and the candidates when there are several and none is requested.
std::string chooseImuTopic(const std::string& bag, const std::vector<BagTopic>& topics, const std::string& imu_type,
                           const std::string& requested);

// One scan of a run: which scan, the stamp the run gives it, and whether the run plays it reversed.
struct PlayedScan {
  size_t index;
  double stamp;
  bool reversed = false;
};

// The scans a run plays, in order: every `stride`-th scan from scan `first` (a faster drive, or dropped
// frames; a drive cut mid-way) and, with `reverse`, last to first; at most `max_frames` of them (0: all).
// A reverse run drives the route backwards rather than back in time: its stamps are mirrored about the
// played span, so they still advance by the recorded intervals, and each sweep is mirrored too
// (asPlayed(), reverseSweepDirection()). Throws std::invalid_argument for a stride of 0.
std::vector<PlayedScan> playOrder(const ScanSource& source, size_t stride, bool reverse, size_t max_frames = 0,
                                  size_t first = 0);

// The scan `cloud`, read for `played`, as the run plays it: at the played stamp and, reversed, with its
// sweep running backwards in time as well. Within the sweep the sensor moved forward along the route,
// which the reverse run drives backwards, so a sweep deskewed with its recorded per-point times would be
// smeared twice over instead of straightened (0.5 m of forward-backward gap over 107 m of a real KITTI
// drive, 17 m over 347 m): each point's time relative to the stamp changes sign.
void asPlayed(const PlayedScan& played, PointCloud& cloud);

// The same for a sensor whose points are timed by their azimuth (deskew.time_source azimuth): in a
// reverse run it turns the other way.
void reverseSweepDirection(SensorConfig& sensor);

}  // namespace elo
