// PCD scans: read by elo_io's own parser (src/io/pcd_format.hpp says why not PCL's), written through
// PCL; neither is in this header, so users of elo_io do not compile PCL.
#pragma once

#include <cstddef>
#include <string>

#include "elo/types.hpp"

namespace elo {

// Reads x, y, z (float32 or float64), and when present `intensity` (any numeric type), `ring` (any
// integer type; a value outside 0..65535 becomes kUnknownRing) and `time` or `t` (floating point
// seconds, or integer nanoseconds as Ouster writes), from ascii, binary or binary_compressed data. A
// malformed file throws IoError naming the file (and the line for header and ascii problems).
// Points with a non-finite coordinate are skipped and counted into `non_finite_skipped`; when that is
// null and points were skipped, a warning naming the file goes to stderr, so a skip is never silent.
PointCloud readPcd(const std::string& path, size_t* non_finite_skipped = nullptr);

// Binary PCD with x y z intensity (float32), plus `ring` (uint16) and `time` (float32 s) when the
// cloud has them.
void writePcd(const std::string& path, const PointCloud& cloud);

}  // namespace elo
