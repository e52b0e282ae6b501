// elo_run --map: the drive's map the session built (docs/map.md), written when the run ends or fails
// part-way, with what it cost.
#pragma once

#include <string>
#include <utility>

#include "elo/drive_session.hpp"

namespace elo::tools {

// Writes the session's drive map to `path`; returns what was written, for the summary.
std::string writeDriveMap(DriveSession& session, const std::string& path);

// A failed run still writes the map of the scans before the failure; a map that cannot be written then
// is reported, and the run's own failure is the one that ends it.
void writeDriveMapAfterFailure(DriveSession& session, const std::string& path);

// CPU milliseconds a processed scan, taken by the map or not: copying points on the odometry's thread,
// and adding them on the map's.
std::pair<double, double> mapCostPerScan(DriveSession& session);

}  // namespace elo::tools
