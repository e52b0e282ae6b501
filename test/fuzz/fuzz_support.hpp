// What the fuzz targets share. A target returns normally for an input the code under test handles (a
// result, or the reader's documented error); a violated property aborts, which libFuzzer reports as a
// crash and the replay driver as a failed test.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace elo::fuzz {

// The name error messages give the input in place of a file.
inline const char* const kInputName = "fuzz input";

inline void expectProperty(bool holds, const char* property) {
  if (!holds) {
    std::fprintf(stderr, "fuzz property violated: %s\n", property);
    std::abort();
  }
}

inline std::string bytesAsString(const uint8_t* data, size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

}  // namespace elo::fuzz
