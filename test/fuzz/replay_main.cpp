// Replays inputs through a fuzz target's LLVMFuzzerTestOneInput without libFuzzer, so that the GCC build
// (and its sanitizer build) runs the corpus and every past crasher as a ctest test.
//   TARGET PATH...   each PATH is a file or a directory whose files are all run, in name order.
// A PATH that does not exist is skipped with a note (a target may have no crashers yet), but a run that
// finds no input at all fails: a renamed corpus must not pass by testing nothing.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputsUnder(const fs::path& path) {
  std::vector<fs::path> inputs;
  if (fs::is_regular_file(path)) {
    inputs.push_back(path);
  } else if (fs::is_directory(path)) {
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(path)) {
      if (entry.is_regular_file()) inputs.push_back(entry.path());
    }
    std::sort(inputs.begin(), inputs.end());
  } else {
    std::cout << "note: " << path << " does not exist, nothing to replay there\n";
  }
  return inputs;
}

std::vector<uint8_t> readBytes(const fs::path& path) {
  std::ifstream stream(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
}

}  // namespace

int main(int argc, char** argv) {
  size_t replayed = 0;
  for (int i = 1; i < argc; ++i) {
    for (const fs::path& input : inputsUnder(argv[i])) {
      // Printed first, so that a crash names the input that caused it.
      std::cout << "replaying " << input.string() << std::endl;
      const std::vector<uint8_t> bytes = readBytes(input);
      LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
      ++replayed;
    }
  }
  std::cout << replayed << " inputs replayed\n";
  return replayed > 0 ? 0 : 1;
}
