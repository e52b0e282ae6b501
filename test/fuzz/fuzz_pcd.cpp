// The PCD reader on arbitrary bytes: a scan or an IoError, never a crash. A scan holds only finite
// points, and each optional channel is empty or has one value per point.
#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "elo/io/io_error.hpp"
#include "elo/io/pcd.hpp"
#include "fuzz_support.hpp"

namespace {

// readPcd takes a path (it reads whole files), so every input is written to one temporary file, removed
// when the process ends normally.
class ScratchFile {
 public:
  ScratchFile() {
    path_ = (std::filesystem::temp_directory_path() / "elo_fuzz_pcd_XXXXXX").string();
    const int descriptor = mkstemp(path_.data());
    elo::fuzz::expectProperty(descriptor >= 0, "a temporary file can be created");
    close(descriptor);
  }
  ~ScratchFile() { std::remove(path_.c_str()); }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  const std::string& write(const uint8_t* data, size_t size) {
    std::ofstream(path_, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data),
                                                                   static_cast<std::streamsize>(size));
    return path_;
  }

 private:
  std::string path_;
};

bool emptyOrOnePerPoint(size_t channel_size, size_t points) { return channel_size == 0 || channel_size == points; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using elo::fuzz::expectProperty;
  static ScratchFile scratch;
  try {
    size_t non_finite = 0;
    const elo::PointCloud cloud = elo::readPcd(scratch.write(data, size), &non_finite);
    for (const elo::Vec3f& point : cloud.points) {
      expectProperty(point.allFinite(), "only finite points");
    }
    expectProperty(emptyOrOnePerPoint(cloud.intensity.size(), cloud.size()), "intensity empty or one per point");
    expectProperty(emptyOrOnePerPoint(cloud.ring.size(), cloud.size()), "ring empty or one per point");
    expectProperty(emptyOrOnePerPoint(cloud.time.size(), cloud.size()), "time empty or one per point");
  } catch (const elo::IoError&) {
    // The clear error a malformed file must give.
  }
  return 0;
}
