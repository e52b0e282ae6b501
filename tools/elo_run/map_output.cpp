#include "map_output.hpp"

#include <algorithm>
#include <cstdio>

#include "elo/io/map_pcd.hpp"

namespace elo::tools {

std::string writeDriveMap(DriveSession& session, const std::string& path) {
  MapBuilder& builder = *session.driveMap();
  const MapCloud map = builder.points();
  writeMapPcd(path, map);
  const MapBuilder::Statistics statistics = builder.statistics();
  char text[400];
  std::snprintf(text, sizeof(text),
                "map: %zu points of %zu voxels from %zu scans (%zu degenerate scans left out, %zu dropped) in %.0f MiB, "
                "written to %s",
                map.size(), statistics.voxels, statistics.scans, session.mapFeedStatistics().degenerate,
                statistics.dropped, statistics.memory_bytes / 1048576.0, path.c_str());
  return text;
}

void writeDriveMapAfterFailure(DriveSession& session, const std::string& path) {
  try {
    std::fprintf(stderr, "elo_run: %s\n", writeDriveMap(session, path).c_str());
  } catch (const std::exception& error) {
    std::fprintf(stderr, "elo_run: cannot write the map: %s\n", error.what());
  }
}

std::pair<double, double> mapCostPerScan(DriveSession& session) {
  const MapBuilder::Statistics statistics = session.driveMap()->statistics();
  const MapFeedStatistics& fed = session.mapFeedStatistics();
  const double scans = std::max<double>(fed.processed, 1.0);
  return {1000.0 * fed.copy_seconds / scans, 1000.0 * statistics.busy_seconds / scans};
}

}  // namespace elo::tools
