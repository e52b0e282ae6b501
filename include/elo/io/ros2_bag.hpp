// A ROS 2 bag as a source of scans: a directory with metadata.yaml and the bag's SQLite files (*.db3,
// several when the recording was split), holding sensor_msgs/msg/PointCloud2 in CDR. Read with SQLite
// and our own CDR decoder (Debian 12 has no ROS 2). MCAP storage is refused with the command that
// converts it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "elo/io/bag_imu.hpp"
#include "elo/io/scan_source.hpp"

namespace elo {

namespace ros2_bag_detail {
class File;  // one .db3 file of a bag, open for the whole run
}  // namespace ros2_bag_detail

// The message types of ROS 2 clouds and IMUs, as a bag's topics table names them.
inline const char* const kRos2CloudType = "sensor_msgs/msg/PointCloud2";
inline const char* const kRos2ImuType = "sensor_msgs/msg/Imu";

// True when `path` is a directory holding metadata.yaml: what `ros2 bag record` writes.
bool isRos2Bag(const std::string& path);

// The sensor_msgs/msg/Imu messages of the ROS 2 bag `directory`, for elo_run's IMU (docs/imu.md): the
// samples of `topic` (empty: the bag's only Imu topic; none when it has none), decoded by decodeCdrImu().
// A message that cannot be read (malformed CDR, SQLite cannot give it) or says it has no angular velocity
// is skipped and counted; a file damaged part-way gives the messages before the damage, and `warning`
// says so. Throws IoError as the Ros2Bag constructor does for the bag, for a `topic` that is no Imu topic
// of it (the message lists its topics), several Imu topics and none named (the message lists them), or an
// Imu topic not serialized as CDR.
BagImu readRos2BagImu(const std::string& directory, const std::string& topic, std::string& warning);

class Ros2Bag : public ScanSource {
 public:
  // Opens every .db3 file of `directory` and lists the clouds of `topic` (empty: the bag's only
  // PointCloud2 topic) in header-stamp order. Throws IoError for MCAP storage, no .db3 file, a file SQLite
  // cannot open, no such topic (the message lists the bag's topics) or no message on it. A file damaged
  // part-way (a copy cut short) gives the messages SQLite reaches before the damage, and warning() says
  // so; where its message table cannot be followed at all, none, and the error says why.
  Ros2Bag(const std::string& directory, const std::string& topic);
  ~Ros2Bag() override;

  size_t size() const override { return messages_.size(); }
  double stamp(size_t index) const override;
  // Decodes and converts the message (elo::convertPointCloud2); UnusableScan when it cannot.
  LoadedScan read(size_t index) const override;
  std::string describe() const override;
  std::string warning() const override { return warning_; }

 private:
  using File = ros2_bag_detail::File;
  struct Message {
    size_t file;
    int64_t row;
    double stamp;   // the header stamp; the recording time when the header cannot be read
  };

  void listMessages();

  std::string directory_;
  std::string topic_;
  std::vector<std::unique_ptr<File>> files_;
  std::vector<Message> messages_;
  std::string warning_;
};

}  // namespace elo
