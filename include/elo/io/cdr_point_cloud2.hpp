// sensor_msgs/msg/PointCloud2 as ROS 2 serializes it in a bag: plain CDR (XCDR1), little- or big-endian
// as its 4-byte encapsulation header says, each primitive aligned to its size counted from the end of
// that header. A decoder of our own (Debian 12 has no ROS 2): it reads untrusted bytes, so every length is
// checked against what is left, and test/fuzz/fuzz_cdr_point_cloud2 fuzzes it.
#pragma once

#include <cstddef>
#include <cstdint>

#include "elo/io/point_cloud2.hpp"

namespace elo {

// The header stamp, from the first bytes of the message only, so that a bag's messages can be put in
// stamp order without reading their points. Throws IoError when the bytes are not such a message.
double decodeCdrStamp(const uint8_t* data, size_t size);

// The whole message as elo::convertPointCloud2 reads it; the view borrows the point bytes from `data`.
// Throws IoError naming what is malformed and at which byte.
PointCloud2View decodeCdrPointCloud2(const uint8_t* data, size_t size);

}  // namespace elo
