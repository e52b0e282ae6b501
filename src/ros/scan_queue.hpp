// The clouds between the subscriber callback and the odometry worker. The callback only queues, so the
// nodelet manager's threads never wait for a registration; the worker takes the clouds in order.
#pragma once

#include <sensor_msgs/PointCloud2.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>

namespace elo_ros {

struct QueuedCloud {
  sensor_msgs::PointCloud2ConstPtr message;
  std::chrono::steady_clock::time_point received;  // for the latency the diagnostics report
};

class ScanQueue {
 public:
  // capacity 0: keeps every cloud (bag replay); 1: keeps only the latest (live sensor).
  explicit ScanQueue(size_t capacity) : capacity_(capacity) {}

  // Returns how many queued clouds the new one replaced (dropped) to stay within the capacity.
  size_t push(QueuedCloud cloud) {
    size_t dropped = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (closed_) return 0;
      while (capacity_ > 0 && clouds_.size() >= capacity_) {
        clouds_.pop_front();
        ++dropped;
      }
      clouds_.push_back(std::move(cloud));
    }
    ready_.notify_one();
    return dropped;
  }

  // Waits for the next cloud. After close(), returns what is still queued, then nothing.
  std::optional<QueuedCloud> pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [this] { return closed_ || !clouds_.empty(); });
    if (clouds_.empty()) return std::nullopt;
    QueuedCloud cloud = std::move(clouds_.front());
    clouds_.pop_front();
    return cloud;
  }

  // Refuses new clouds; the worker finishes the queued ones and stops.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  size_t size() {
    std::lock_guard<std::mutex> lock(mutex_);
    return clouds_.size();
  }

 private:
  const size_t capacity_;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<QueuedCloud> clouds_;
  bool closed_ = false;
};

}  // namespace elo_ros
