// Opens what elo_run's --input names: a ROS 1 bag (*.bag), a ROS 2 bag (a directory with metadata.yaml,
// or one of its .db3 files), or a sequence directory. Here, beside the ROS 1 reader, because only the ROS layer may read ROS 1 bags.
#pragma once

#include <memory>
#include <string>

#include "elo/io/scan_source.hpp"

namespace elo_ros {

// `topic`: the bag topic to read (empty: the bag's only PointCloud2 topic); a sequence directory has
// none, and naming one is an error. An .mcap file is refused with the command that converts it. Throws
// elo::IoError.
std::unique_ptr<elo::ScanSource> openScanSource(const std::string& input, const std::string& topic);

}  // namespace elo_ros
