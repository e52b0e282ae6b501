// A ROS 2 bag's Imu message bytes -> what elo_run takes of it: any bytes are decoded or rejected with an
// IoError, never a crash (nor a read past them: the sanitized fuzz build checks it). A decoded message's
// stamp is what a header's int32 seconds and uint32 nanoseconds allow, and bytes after the message change
// nothing of it (a recorder may pad).
#include <cmath>
#include <cstring>
#include <vector>

#include "elo/io/cdr_imu.hpp"
#include "elo/io/io_error.hpp"
#include "fuzz_support.hpp"

namespace {

// Bit for bit, so that a NaN read from the bytes equals itself.
bool sameBits(const elo::CdrImu& a, const elo::CdrImu& b) {
  return std::memcmp(&a.stamp, &b.stamp, sizeof(double)) == 0 &&
         std::memcmp(a.angular_velocity.data(), b.angular_velocity.data(), 3 * sizeof(double)) == 0 &&
         std::memcmp(a.linear_acceleration.data(), b.linear_acceleration.data(), 3 * sizeof(double)) == 0 &&
         a.has_angular_velocity == b.has_angular_velocity;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using elo::fuzz::expectProperty;
  elo::CdrImu message;
  try {
    message = elo::decodeCdrImu(data, size);
  } catch (const elo::IoError&) {
    return 0;  // the clear error a malformed message must give
  }
  expectProperty(std::isfinite(message.stamp) && std::abs(message.stamp) < 2.2e9,
                 "the stamp is an int32 of seconds and a uint32 of nanoseconds");
  std::vector<uint8_t> padded(data, data + size);
  padded.insert(padded.end(), 8, 0xAB);
  expectProperty(sameBits(elo::decodeCdrImu(padded.data(), padded.size()), message),
                 "bytes after the message change nothing");
  return 0;
}
