// A ROS 2 bag's message bytes -> elo::PointCloud: the CDR decoder, then the conversion, as elo_run's
// ROS 2 bag reader runs them. Any bytes are decoded or rejected with an IoError, never a crash; a decoded
// message is converted or rejected with a reason; a converted cloud holds only finite points, each
// optional channel empty or one value per point, and accounts for every point. The stamp read alone is
// the stamp the whole message gives.
#include <cmath>

#include "elo/io/cdr_point_cloud2.hpp"
#include "elo/io/io_error.hpp"
#include "elo/io/point_cloud2.hpp"
#include "converted_cloud_properties.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using elo::fuzz::expectProperty;
  elo::PointCloud2View message;
  try {
    message = elo::decodeCdrPointCloud2(data, size);
  } catch (const elo::IoError&) {
    return 0;  // the clear error a malformed message must give
  }
  expectProperty(message.data >= data && message.data + message.data_size <= data + size,
                 "the point bytes lie inside the message");
  const double stamp = elo::decodeCdrStamp(data, size);
  expectProperty(stamp == message.stamp || (std::isnan(stamp) && std::isnan(message.stamp)),
                 "the stamp read alone is the message's");
  elo::fuzz::expectConvertedOrRejected(elo::convertPointCloud2(message),
                                       static_cast<size_t>(message.width) * message.height);
  return 0;
}
