#include "elo/io/ros2_bag.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>

#include "elo/io/cdr_imu.hpp"
#include "elo/io/cdr_point_cloud2.hpp"
#include "elo/io/point_cloud2.hpp"

namespace elo {
namespace {

namespace fs = std::filesystem;

// Enough bytes for the encapsulation header and header.stamp: what listing needs of each message.
constexpr int kStampBytes = 12;

std::vector<std::string> filesWithExtension(const std::string& directory, const std::string& extension) {
  std::vector<std::string> paths;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory)) {
    if (entry.is_regular_file() && entry.path().extension() == extension) paths.push_back(entry.path().string());
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

// A prepared statement, finalized when it goes out of scope.
class Statement {
 public:
  Statement(sqlite3* database, const char* sql, const std::string& path) {
    if (sqlite3_prepare_v2(database, sql, -1, &statement_, nullptr) != SQLITE_OK) {
      throw IoError("'" + path + "' is not a ROS 2 bag file SQLite can read: " + sqlite3_errmsg(database));
    }
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  sqlite3_stmt* get() const { return statement_; }

 private:
  sqlite3_stmt* statement_ = nullptr;
};

}  // namespace

namespace ros2_bag_detail {

// One .db3 file, open read-only for the whole run.
class File {
 public:
  explicit File(std::string path) : path_(std::move(path)) {
    if (sqlite3_open_v2(path_.c_str(), &database_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      const std::string reason = database_ != nullptr ? sqlite3_errmsg(database_) : "out of memory";
      sqlite3_close(database_);
      throw IoError("cannot open '" + path_ + "': " + reason);
    }
    // SQLite refuses a whole file that is shorter than its header says (a copy cut short) unless the
    // schema is writable; then it reads it up to the cut. The connection stays read-only.
    sqlite3_exec(database_, "PRAGMA writable_schema=ON", nullptr, nullptr, nullptr);
  }
  ~File() {
    sqlite3_blob_close(blob_);
    sqlite3_close(database_);
  }
  File(const File&) = delete;
  File& operator=(const File&) = delete;

  const std::string& path() const { return path_; }
  sqlite3* database() const { return database_; }

  // Each topic's id in this file, with its type and serialization format.
  struct Topic {
    int64_t id;
    std::string name, type, format;
  };
  std::vector<Topic> topics() const {
    Statement statement(database_, "SELECT id, name, type, serialization_format FROM topics", path_);
    std::vector<Topic> topics;
    int status;
    while ((status = sqlite3_step(statement.get())) == SQLITE_ROW) {
      topics.push_back({sqlite3_column_int64(statement.get(), 0), text(statement, 1), text(statement, 2),
                        text(statement, 3)});
    }
    if (status != SQLITE_DONE) throw IoError("cannot read the topics of '" + path_ + "': " + sqlite3_errmsg(database_));
    return topics;
  }

  size_t messageCount(int64_t topic_id) const {
    Statement statement(database_, "SELECT COUNT(*) FROM messages WHERE topic_id = ?", path_);
    sqlite3_bind_int64(statement.get(), 1, topic_id);
    if (sqlite3_step(statement.get()) != SQLITE_ROW) return 0;  // a damaged file: listing says where
    return static_cast<size_t>(sqlite3_column_int64(statement.get(), 0));
  }

  // The message's bytes, read with incremental blob I/O straight into the buffer (one copy); empty, with
  // `error` set, when SQLite cannot read them.
  std::vector<uint8_t> message(int64_t row, std::string& error) const {
    const int opened = blob_ == nullptr ? sqlite3_blob_open(database_, "main", "messages", "data", row, 0, &blob_)
                                        : sqlite3_blob_reopen(blob_, row);
    std::vector<uint8_t> bytes;
    if (opened == SQLITE_OK) {
      bytes.resize(static_cast<size_t>(sqlite3_blob_bytes(blob_)));
      if (sqlite3_blob_read(blob_, bytes.data(), static_cast<int>(bytes.size()), 0) == SQLITE_OK) return bytes;
    }
    error = sqlite3_errmsg(database_);
    sqlite3_blob_close(blob_);  // a failed reopen leaves the handle unusable
    blob_ = nullptr;
    return {};
  }

 private:
  static std::string text(const Statement& statement, int column) {
    const unsigned char* value = sqlite3_column_text(statement.get(), column);
    return value == nullptr ? "" : reinterpret_cast<const char*>(value);
  }

  std::string path_;
  sqlite3* database_ = nullptr;
  mutable sqlite3_blob* blob_ = nullptr;  // the last message read, reopened on the next
};

}  // namespace ros2_bag_detail

namespace {

using ros2_bag_detail::File;

// Every .db3 file of the bag `directory`, open. Throws IoError for MCAP storage, no .db3 file, or a file
// SQLite cannot open.
std::vector<std::unique_ptr<File>> openBagFiles(const std::string& directory) {
  const std::vector<std::string> paths = filesWithExtension(directory, ".db3");
  if (paths.empty()) {
    if (!filesWithExtension(directory, ".mcap").empty()) {
      throw IoError("ROS 2 bag '" + directory + "' is stored as MCAP, which elo_run does not read: convert it to "
                    "SQLite with `ros2 bag convert` (storage_id: sqlite3)");
    }
    throw IoError("ROS 2 bag '" + directory + "' holds no .db3 file");
  }
  std::vector<std::unique_ptr<File>> files;
  for (const std::string& path : paths) files.push_back(std::make_unique<File>(path));
  return files;
}

// The bag's topics over all its files, each with its message count. Throws IoError when a topic of
// `cdr_type` is serialized other than as CDR.
std::vector<BagTopic> topicsOf(const std::vector<std::unique_ptr<File>>& files, const char* cdr_type) {
  std::map<std::string, BagTopic> topics;
  for (const auto& file : files) {
    for (const File::Topic& entry : file->topics()) {
      BagTopic& listed = topics[entry.name];
      listed.name = entry.name;
      listed.type = entry.type;
      listed.messages += file->messageCount(entry.id);
      if (entry.type == cdr_type && entry.format != "cdr") {
        throw IoError("topic " + entry.name + " of '" + file->path() + "' is serialized as '" + entry.format +
                      "'; elo_run reads CDR, what ROS 2 records");
      }
    }
  }
  std::vector<BagTopic> listed;
  for (const auto& [name, entry] : topics) listed.push_back(entry);
  return listed;
}

// The id `topic` has in `file`; none when it was recorded in another file of the bag.
std::optional<int64_t> topicId(const File& file, const std::string& topic) {
  for (const File::Topic& entry : file.topics()) {
    if (entry.name == topic) return entry.id;
  }
  return std::nullopt;
}

std::string damaged(const File& file) {
  return "'" + file.path() + "' is damaged (SQLite: " + sqlite3_errmsg(file.database()) +
         "; a copy cut short?): its messages past the damage are left out";
}

}  // namespace

bool isRos2Bag(const std::string& path) {
  return fs::is_directory(path) && fs::exists(fs::path(path) / "metadata.yaml");
}

Ros2Bag::Ros2Bag(const std::string& directory, const std::string& topic)
    : directory_(directory), files_(openBagFiles(directory)) {
  const std::vector<BagTopic> listed = topicsOf(files_, kRos2CloudType);
  topic_ = chooseCloudTopic("ROS 2 bag '" + directory_ + "'", listed, kRos2CloudType, topic);
  listMessages();
  if (messages_.empty()) throw IoError(describe() + " holds no message" + (warning_.empty() ? "" : " (" + warning_ + ")"));
}

Ros2Bag::~Ros2Bag() = default;

// Lists the topic's messages file by file in row order, each with the header stamp read from its first
// bytes (incremental blob I/O reads no further), then sorts them by stamp. In row order, a damaged file
// gives the messages SQLite reaches before the damage.
void Ros2Bag::listMessages() {
  for (size_t index = 0; index < files_.size(); ++index) {
    const File& file = *files_[index];
    const std::optional<int64_t> topic = topicId(file, topic_);
    if (!topic) continue;  // recorded in another file of the bag
    // In row order, which SQLite reads as the table is stored, one row at a time.
    Statement rows(file.database(), "SELECT id, timestamp FROM messages WHERE topic_id = ? ORDER BY id", file.path());
    sqlite3_bind_int64(rows.get(), 1, *topic);
    int status;
    while ((status = sqlite3_step(rows.get())) == SQLITE_ROW) {
      const int64_t row = sqlite3_column_int64(rows.get(), 0);
      double stamp = static_cast<double>(sqlite3_column_int64(rows.get(), 1)) * 1e-9;  // recording time, ns
      sqlite3_blob* blob = nullptr;
      uint8_t bytes[kStampBytes];
      if (sqlite3_blob_open(file.database(), "main", "messages", "data", row, 0, &blob) == SQLITE_OK &&
          sqlite3_blob_bytes(blob) >= kStampBytes && sqlite3_blob_read(blob, bytes, kStampBytes, 0) == SQLITE_OK) {
        try {
          stamp = decodeCdrStamp(bytes, kStampBytes);
        } catch (const IoError&) {
          // Not a CDR message: it keeps its recording time, and reading it says what is wrong.
        }
      }
      sqlite3_blob_close(blob);
      messages_.push_back({index, row, stamp});
    }
    if (status != SQLITE_DONE) warning_ += (warning_.empty() ? "" : "; ") + damaged(file);
  }
  std::stable_sort(messages_.begin(), messages_.end(),
                   [](const Message& a, const Message& b) { return a.stamp < b.stamp; });
}

double Ros2Bag::stamp(size_t index) const { return messages_.at(index).stamp; }

std::string Ros2Bag::describe() const { return "ROS 2 bag '" + directory_ + "', topic " + topic_; }

BagImu readRos2BagImu(const std::string& directory, const std::string& topic, std::string& warning) {
  const std::vector<std::unique_ptr<File>> files = openBagFiles(directory);
  const std::string bag = "ROS 2 bag '" + directory + "'";
  BagImu imu;
  imu.topic = chooseImuTopic(bag, topicsOf(files, kRos2ImuType), kRos2ImuType, topic);
  if (imu.topic.empty()) return imu;
  for (const auto& file : files) {
    const std::optional<int64_t> id = topicId(*file, imu.topic);
    if (!id) continue;
    // Whole messages, in row order: an Imu message is some 300 bytes.
    Statement rows(file->database(), "SELECT id, data FROM messages WHERE topic_id = ? ORDER BY id", file->path());
    sqlite3_bind_int64(rows.get(), 1, *id);
    int status;
    while ((status = sqlite3_step(rows.get())) == SQLITE_ROW) {
      const auto* data = static_cast<const uint8_t*>(sqlite3_column_blob(rows.get(), 1));
      const size_t size = static_cast<size_t>(sqlite3_column_bytes(rows.get(), 1));
      try {
        const CdrImu message = decodeCdrImu(data, size);
        if (!message.has_angular_velocity) {
          imu.skip(imu_message::kNoAngularVelocity);
          continue;
        }
        imu.samples.push_back({message.stamp, message.angular_velocity, message.linear_acceleration});
      } catch (const IoError& malformed) {
        imu.skip(imu_message::kUnreadable, bag + ", topic " + imu.topic + ", message " +
                                               std::to_string(sqlite3_column_int64(rows.get(), 0)) + " of '" +
                                               file->path() + "': " + malformed.what());
      }
    }
    if (status != SQLITE_DONE) warning += (warning.empty() ? "" : "; ") + damaged(*file);
  }
  imu.sortByStamp();
  return imu;
}

LoadedScan Ros2Bag::read(size_t index) const {
  const Message& message = messages_.at(index);
  const std::string where = describe() + ", message " + std::to_string(message.row) + " of '" +
                            files_[message.file]->path() + "'";
  std::string error;
  const std::vector<uint8_t> bytes = files_[message.file]->message(message.row, error);
  if (!error.empty()) throw UnusableScan("message unreadable", where + ": " + error);
  PointCloud2View view;
  try {
    view = decodeCdrPointCloud2(bytes.data(), bytes.size());
  } catch (const IoError& malformed) {
    throw UnusableScan("message unreadable", where + ": " + malformed.what());
  }
  ConvertedCloud converted = convertPointCloud2(view);
  if (!converted.usable()) throw UnusableScan(elo::describe(converted.problem), where + ": " + converted.detail);
  return {std::move(converted.cloud), converted.non_finite_points, converted.time_problem};
}

}  // namespace elo
