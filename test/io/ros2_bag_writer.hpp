// Test helpers that write what ROS 2 records, without ROS 2: a CDR encoder of sensor_msgs/msg/PointCloud2
// and a ROS 2 bag (metadata.yaml and an SQLite .db3 with rosbag2's schema). Test code only: elo_run reads
// bags, it never writes them.
#pragma once

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "elo/imu/imu_track.hpp"
#include "elo/io/point_cloud2.hpp"
#include "elo/types.hpp"

namespace elo::test {

// Writes plain CDR: the encapsulation header, then each primitive aligned to its size counted from the
// end of that header, in the chosen byte order.
class CdrWriter {
 public:
  explicit CdrWriter(bool big_endian) : swap_(big_endian != hostIsBigEndian()) {
    bytes_ = {0, static_cast<uint8_t>(big_endian ? 0 : 1), 0, 0};
  }

  template <typename T>
  void write(T value) {
    while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_.push_back(0);
    uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (swap_) std::reverse(raw, raw + sizeof(T));
    bytes_.insert(bytes_.end(), raw, raw + sizeof(T));
  }
  void writeString(const std::string& text) {
    write<uint32_t>(static_cast<uint32_t>(text.size() + 1));
    bytes_.insert(bytes_.end(), text.begin(), text.end());
    bytes_.push_back(0);
  }
  void writeBytes(const std::vector<uint8_t>& data) {
    write<uint32_t>(static_cast<uint32_t>(data.size()));
    bytes_.insert(bytes_.end(), data.begin(), data.end());
  }
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  bool swap_;
  std::vector<uint8_t> bytes_;
};

// A header stamp split as ros::Time::fromSec splits it, so that a ROS 2 bag's stamps equal those
// kitti_to_bag writes into a ROS 1 bag for the same scan times.
struct Stamp {
  int32_t sec;
  uint32_t nanosec;
};
inline Stamp stampOf(double seconds) {
  const int64_t whole = static_cast<int64_t>(std::floor(seconds));
  uint64_t nanoseconds = static_cast<uint64_t>(std::llround((seconds - static_cast<double>(whole)) * 1e9));
  return {static_cast<int32_t>(whole + static_cast<int64_t>(nanoseconds / 1000000000ull)),
          static_cast<uint32_t>(nanoseconds % 1000000000ull)};
}

// A cloud packed as kitti_to_bag packs it (x y z intensity float32, ring uint16, time float32, each
// naturally aligned; optional fields only when present), in the chosen byte order for the points, and
// CDR-encoded in the chosen byte order for the message.
inline std::vector<uint8_t> encodeCdrPointCloud2(const PointCloud& cloud, Stamp stamp, bool big_endian_cdr = false,
                                                 bool big_endian_points = false) {
  struct Field {
    const char* name;
    uint32_t offset;
    uint8_t datatype;
  };
  std::vector<Field> fields = {{"x", 0, point_field::kFloat32}, {"y", 4, point_field::kFloat32}, {"z", 8, point_field::kFloat32}};
  uint32_t step = 12;
  if (!cloud.intensity.empty()) fields.push_back({"intensity", step, point_field::kFloat32}), step += 4;
  if (!cloud.ring.empty()) fields.push_back({"ring", step, point_field::kUint16}), step += 2;
  if (!cloud.time.empty()) step = (step + 3) / 4 * 4, fields.push_back({"time", step, point_field::kFloat32}), step += 4;
  step = (step + 3) / 4 * 4;
  std::vector<uint8_t> data(static_cast<size_t>(step) * cloud.size());
  const bool swap = big_endian_points != hostIsBigEndian();
  const auto put = [&](uint8_t* at, const auto value) {
    std::memcpy(at, &value, sizeof(value));
    if (swap) std::reverse(at, at + sizeof(value));
  };
  for (size_t i = 0; i < cloud.size(); ++i) {
    uint8_t* point = data.data() + i * step;
    size_t field = 0;
    for (int axis = 0; axis < 3; ++axis) put(point + fields[field++].offset, cloud.points[i][axis]);
    if (!cloud.intensity.empty()) put(point + fields[field++].offset, cloud.intensity[i]);
    if (!cloud.ring.empty()) put(point + fields[field++].offset, cloud.ring[i]);
    if (!cloud.time.empty()) put(point + fields[field++].offset, cloud.time[i]);
  }
  CdrWriter writer(big_endian_cdr);
  writer.write<int32_t>(stamp.sec);
  writer.write<uint32_t>(stamp.nanosec);
  writer.writeString("velodyne");
  writer.write<uint32_t>(1);                                    // height
  writer.write<uint32_t>(static_cast<uint32_t>(cloud.size()));  // width
  writer.write<uint32_t>(static_cast<uint32_t>(fields.size()));
  for (const Field& field : fields) {
    writer.writeString(field.name);
    writer.write<uint32_t>(field.offset);
    writer.write<uint8_t>(field.datatype);
    writer.write<uint32_t>(1);
  }
  writer.write<uint8_t>(big_endian_points ? 1 : 0);
  writer.write<uint32_t>(step);
  writer.write<uint32_t>(static_cast<uint32_t>(data.size()));  // row_step
  writer.writeBytes(data);
  writer.write<uint8_t>(1);  // is_dense
  return writer.bytes();
}

// A sensor_msgs/msg/Imu as a driver publishes it: no orientation (orientation_covariance[0] = -1, as
// REP-145 asks), the covariances zero but `angular_velocity_covariance0` (-1: no angular velocity).
inline std::vector<uint8_t> encodeCdrImu(const ImuSample& sample, Stamp stamp, bool big_endian = false,
                                         double angular_velocity_covariance0 = 0.0) {
  CdrWriter writer(big_endian);
  writer.write<int32_t>(stamp.sec);
  writer.write<uint32_t>(stamp.nanosec);
  writer.writeString("imu");
  for (double q : {0.0, 0.0, 0.0, 1.0}) writer.write<double>(q);
  const auto write_covariance = [&](double first) {
    writer.write<double>(first);
    for (int i = 1; i < 9; ++i) writer.write<double>(0.0);
  };
  write_covariance(-1.0);
  for (int axis = 0; axis < 3; ++axis) writer.write<double>(sample.angular_velocity[axis]);
  write_covariance(angular_velocity_covariance0);
  for (int axis = 0; axis < 3; ++axis) writer.write<double>(sample.specific_force[axis]);
  write_covariance(0.0);
  return writer.bytes();
}

// A ROS 2 bag directory as `ros2 bag record` writes it with the sqlite3 storage: metadata.yaml and
// DIR/<name>_0.db3 with rosbag2's topics and messages tables.
class Ros2BagWriter {
 public:
  explicit Ros2BagWriter(const std::string& directory) {
    std::filesystem::create_directories(directory);
    const std::string name = std::filesystem::path(directory).filename().string();
    std::ofstream(directory + "/metadata.yaml") << "rosbag2_bagfile_information:\n  version: 4\n"
                                                    "  storage_identifier: sqlite3\n  relative_file_paths:\n    - "
                                                 << name << "_0.db3\n";
    check(sqlite3_open((directory + "/" + name + "_0.db3").c_str(), &database_));
    execute("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
            "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
            "data BLOB NOT NULL);"
            "BEGIN");
  }
  ~Ros2BagWriter() { close(); }
  Ros2BagWriter(const Ros2BagWriter&) = delete;
  Ros2BagWriter& operator=(const Ros2BagWriter&) = delete;

  int64_t addTopic(const std::string& name, const std::string& type = "sensor_msgs/msg/PointCloud2",
                   const std::string& format = "cdr") {
    execute("INSERT INTO topics(name, type, serialization_format, offered_qos_profiles) VALUES('" + name + "', '" +
            type + "', '" + format + "', '')");
    return sqlite3_last_insert_rowid(database_);
  }

  void write(int64_t topic, int64_t recorded_ns, const std::vector<uint8_t>& data) {
    sqlite3_stmt* statement = nullptr;
    check(sqlite3_prepare_v2(database_, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)", -1,
                             &statement, nullptr));
    sqlite3_bind_int64(statement, 1, topic);
    sqlite3_bind_int64(statement, 2, recorded_ns);
    sqlite3_bind_blob(statement, 3, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    const int status = sqlite3_step(statement);
    sqlite3_finalize(statement);
    if (status != SQLITE_DONE) throw std::runtime_error(sqlite3_errmsg(database_));
  }

  void close() {
    if (database_ == nullptr) return;
    execute("COMMIT");
    sqlite3_close(database_);
    database_ = nullptr;
  }

 private:
  void execute(const std::string& sql) {
    char* error = nullptr;
    if (sqlite3_exec(database_, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
      const std::string message = error != nullptr ? error : "unknown error";
      sqlite3_free(error);
      throw std::runtime_error("sqlite: " + message);
    }
  }
  void check(int status) {
    if (status != SQLITE_OK) throw std::runtime_error(std::string("sqlite: ") + sqlite3_errstr(status));
  }

  sqlite3* database_ = nullptr;
};

}  // namespace elo::test
