// Plain CDR (XCDR1) as ROS 2 serializes its messages in a bag: a 4-byte encapsulation header says the byte
// order, and a primitive of n bytes starts at a multiple of n (at most 8) counted from the end of that
// header. Shared by the decoders of the messages elo_run reads from ROS 2 bags (cdr_point_cloud2.cpp,
// cdr_imu.cpp). The bytes are untrusted: every read is checked against what is left, and a malformed
// message is an IoError naming the message type, the byte and what is wrong.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "elo/io/io_error.hpp"
#include "elo/io/point_cloud2.hpp"

namespace elo::io_detail {

class CdrReader {
 public:
  static constexpr size_t kEncapsulationBytes = 4;

  // `message_type`: what the errors call the message ("PointCloud2", "Imu").
  CdrReader(const uint8_t* data, size_t size, const char* message_type)
      : data_(data), size_(size), message_type_(message_type) {
    if (size < kEncapsulationBytes) fail("shorter than the 4-byte CDR encapsulation header");
    if (data[0] != 0 || data[1] > 1) {
      fail("encapsulation " + std::to_string(data[0]) + "," + std::to_string(data[1]) +
           " is not plain CDR (0,0 big-endian or 0,1 little-endian): ROS 2 bags hold plain CDR");
    }
    swap_bytes_ = (data[1] == 0) != hostIsBigEndian();
    position_ = kEncapsulationBytes;
  }

  template <typename T>
  T read(const char* what) {
    align(sizeof(T));
    require(sizeof(T), what);
    uint8_t bytes[sizeof(T)];
    std::memcpy(bytes, data_ + position_, sizeof(T));
    if (swap_bytes_) std::reverse(bytes, bytes + sizeof(T));
    position_ += sizeof(T);
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }

  bool readBool(const char* what) { return read<uint8_t>(what) != 0; }

  // A CDR string: a uint32 length that counts the terminating NUL, the characters, the NUL.
  std::string readString(const char* what) {
    const uint32_t length = read<uint32_t>(what);
    require(length, what);
    const char* characters = reinterpret_cast<const char*>(data_ + position_);
    position_ += length;
    return length == 0 ? std::string() : std::string(characters, strnlen(characters, length - 1));
  }

  // A sequence's element count, checked against the bytes left (each element takes at least
  // `min_element_bytes`), so that a corrupt count cannot make the caller reserve gigabytes.
  uint32_t readCount(size_t min_element_bytes, const char* what) {
    const uint32_t count = read<uint32_t>(what);
    if (static_cast<uint64_t>(count) * min_element_bytes > size_ - position_) {
      fail(std::string(what) + " says " + std::to_string(count) + " elements, but only " +
           std::to_string(size_ - position_) + " bytes follow");
    }
    return count;
  }

  const uint8_t* readBytes(size_t count, const char* what) {
    require(count, what);
    const uint8_t* bytes = data_ + position_;
    position_ += count;
    return bytes;
  }

  // std_msgs/msg/Header's stamp (builtin_interfaces/msg/Time), in seconds as a ROS 1 stamp gives them.
  double readStamp() {
    const int32_t seconds = read<int32_t>("header.stamp.sec");
    const uint32_t nanoseconds = read<uint32_t>("header.stamp.nanosec");
    return stampSeconds(seconds, nanoseconds);
  }

  [[noreturn]] void fail(const std::string& problem) const {
    throw IoError("malformed CDR " + std::string(message_type_) + " (byte " + std::to_string(position_) + " of " +
                  std::to_string(size_) + "): " + problem);
  }

 private:
  void align(size_t alignment) {
    const size_t offset = position_ - kEncapsulationBytes;
    position_ += (alignment - offset % alignment) % alignment;
    position_ = std::min(position_, size_);  // padding past the end: the read that follows fails
  }

  void require(size_t count, const char* what) const {
    if (count > size_ - position_) {
      fail(std::string("truncated in ") + what + ": " + std::to_string(count) + " bytes needed, " +
           std::to_string(size_ - position_) + " left");
    }
  }

  const uint8_t* data_;
  size_t size_;
  const char* message_type_;
  size_t position_ = 0;
  bool swap_bytes_ = false;
};

}  // namespace elo::io_detail
