#include "elo/map/map_builder.hpp"

#include <algorithm>

#include "core/elapsed_time.hpp"

namespace elo {

MapBuilder::MapBuilder(const MapConfig& config, size_t max_queued, AfterScan after_scan)
    : map_(config),
      selection_(config.scan_stride),
      max_queued_(std::max<size_t>(max_queued, 1)),
      after_scan_(std::move(after_scan)),
      thread_([this] { work(); }) {}

MapBuilder::~MapBuilder() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

bool MapBuilder::add(MapScan scan) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queue_.size() >= max_queued_) {
      ++dropped_;
      return false;
    }
    queue_.push_back(std::move(scan));
  }
  changed_.notify_all();
  return true;
}

std::unique_lock<std::mutex> MapBuilder::drained() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return queue_.empty() && !adding_; });
  return lock;
}

MapCloud MapBuilder::points() {
  const std::unique_lock<std::mutex> lock = drained();
  return map_.points();
}

bool MapBuilder::takesNextScan() {
  const std::lock_guard<std::mutex> lock(mutex_);
  return selection_.takes();
}

void MapBuilder::clear() {
  std::unique_lock<std::mutex> lock(mutex_);
  queue_.clear();
  selection_.clear();
  changed_.wait(lock, [this] { return !adding_; });
  map_.clear();
}

MapBuilder::Statistics MapBuilder::statistics() {
  const std::unique_lock<std::mutex> lock = drained();
  return {map_.scanCount(), dropped_, map_.voxelCount(), map_.memoryBytes(), busy_seconds_};
}

void MapBuilder::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, and every scan added
    const MapScan scan = std::move(queue_.front());
    queue_.pop_front();
    adding_ = true;
    // The map is this thread's while adding_ is set: the other calls wait for it to clear.
    lock.unlock();
    const double start = threadCpuSeconds();
    map_.add(scan);
    const double seconds = threadCpuSeconds() - start;
    if (after_scan_) after_scan_(map_, scan);
    lock.lock();
    busy_seconds_ += seconds;
    adding_ = false;
    changed_.notify_all();
  }
}

}  // namespace elo
