// The KITTI .bin reader on arbitrary bytes: a scan or an IoError, never a crash, and a scan holds one
// point and one intensity per 16 bytes.
#include <sstream>

#include "elo/io/io_error.hpp"
#include "elo/io/kitti.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using elo::fuzz::expectProperty;
  std::istringstream stream(elo::fuzz::bytesAsString(data, size));
  try {
    const elo::PointCloud cloud = elo::readKittiBin(stream, elo::fuzz::kInputName);
    expectProperty(cloud.points.size() == size / 16, "one point per 16 bytes");
    expectProperty(cloud.intensity.size() == cloud.points.size(), "one intensity per point");
  } catch (const elo::IoError&) {
    // The clear error a malformed scan must give.
  }
  return 0;
}
