// The text readers of a KITTI sequence and of trajectories (times.txt, poses, TUM poses, calib.txt) on
// arbitrary text: each gives its result or an IoError, never a crash. Every reader sees every input:
// they share the number parsing, and a calib line is also a malformed pose line.
#include <functional>
#include <sstream>

#include "elo/io/io_error.hpp"
#include "elo/io/kitti.hpp"
#include "fuzz_support.hpp"

namespace {

void readOrReject(const std::string& text, const std::function<void(std::istream&)>& read) {
  std::istringstream stream(text);
  try {
    read(stream);
  } catch (const elo::IoError&) {
    // The clear error a malformed file must give.
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using elo::fuzz::kInputName;
  const std::string text = elo::fuzz::bytesAsString(data, size);
  readOrReject(text, [](std::istream& stream) { elo::readTimes(stream, kInputName); });
  readOrReject(text, [](std::istream& stream) { elo::readKittiPoses(stream, kInputName); });
  readOrReject(text, [](std::istream& stream) {
    std::vector<double> stamps;
    const auto poses = elo::readTumPoses(stream, kInputName, &stamps);
    elo::fuzz::expectProperty(stamps.size() == poses.size(), "one TUM stamp per pose");
  });
  readOrReject(text, [](std::istream& stream) { elo::readKittiCalibration(stream, kInputName); });
  return 0;
}
