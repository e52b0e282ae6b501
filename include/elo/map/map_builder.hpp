// The drive's map built on a thread of its own, so that it never delays a pose: the odometry's thread
// copies a processed scan's points out (mapScanOf(): docs/map.md says what it costs) and hands them over;
// this thread adds them to the DriveMap. Scans wait in a bounded queue; when it is
// full (the map's thread starved of CPU for seconds) a scan is left out of the map and counted.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

#include "elo/map/drive_map.hpp"

namespace elo {

class MapBuilder {
 public:
  // Called on the map's thread after each scan is added, before any other call reads the map: the node
  // publishes the thinned map from it. It must not throw.
  using AfterScan = std::function<void(const DriveMap& map, const MapScan& scan)>;

  // Throws ConfigError for an unusable map config.
  explicit MapBuilder(const MapConfig& config, size_t max_queued = 8, AfterScan after_scan = {});
  // Adds the scans still queued, then stops the thread.
  ~MapBuilder();
  MapBuilder(const MapBuilder&) = delete;
  MapBuilder& operator=(const MapBuilder&) = delete;

  // Whether the map takes the next registered scan (MapConfig::scan_stride): ask before copying it out.
  bool takesNextScan();
  // Queues the scan; returns false (and counts it) when the queue is full.
  bool add(MapScan scan);
  // Waits until every scan queued so far is in the map, then returns its points (DriveMap::points()).
  MapCloud points();
  // Forgets the map and the scans still queued, and counts the scans to take from the next one: the
  // odometry restarted at the origin.
  void clear();

  struct Statistics {
    size_t scans = 0;          // added to the map
    size_t dropped = 0;        // left out: the queue was full
    size_t voxels = 0;
    size_t memory_bytes = 0;   // DriveMap::memoryBytes()
    double busy_seconds = 0.0; // CPU time the map's thread spent adding scans
  };
  // Waits until every scan queued so far is in the map.
  Statistics statistics();

 private:
  void work();
  // Waits until the queue is empty and no scan is being added; returns with the lock held.
  std::unique_lock<std::mutex> drained();

  DriveMap map_;
  MapScanSelection selection_;
  size_t max_queued_;
  AfterScan after_scan_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<MapScan> queue_;
  bool adding_ = false;
  bool stopping_ = false;
  size_t dropped_ = 0;
  double busy_seconds_ = 0.0;
  std::thread thread_;  // last: it starts once the members above exist
};

}  // namespace elo
