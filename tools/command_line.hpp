// Command-line handling shared by the tools: `--flag VALUE` pairs and switches read one at a time,
// errors that name the flag, and one exit-code convention (0 success, 1 failure, 2 bad usage).
#pragma once

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace elo::tools {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// `text` read whole as a number of type T, or a UsageError naming `flag`.
template <typename T>
T parseNumber(const std::string& flag, const std::string& text) {
  try {
    size_t used = 0;
    T parsed;
    if constexpr (std::is_integral_v<T>) {
      const long long whole = std::stoll(text, &used);
      if (whole < 0 && std::is_unsigned_v<T>) throw std::out_of_range(text);
      parsed = static_cast<T>(whole);
    } else {
      parsed = static_cast<T>(std::stod(text, &used));
    }
    if (used == text.size()) return parsed;
  } catch (const std::exception&) {
  }
  throw UsageError(flag + " expects " + (std::is_integral_v<T> ? "an integer" : "a number") + ", got '" + text + "'");
}

// `text`, numbers separated by commas ("10,20,50"), each read whole as type T; a UsageError naming
// `flag` for an empty list or a bad number.
template <typename T>
std::vector<T> parseNumberList(const std::string& flag, const std::string& text) {
  std::vector<T> numbers;
  size_t begin = 0;
  while (begin <= text.size()) {
    const size_t comma = std::min(text.find(',', begin), text.size());
    numbers.push_back(parseNumber<T>(flag, text.substr(begin, comma - begin)));
    begin = comma + 1;
  }
  return numbers;
}

class Arguments {
 public:
  Arguments(int argc, char** argv) : argc_(argc), argv_(argv) {}

  // Moves to the next flag; false when none is left.
  bool next() {
    if (++index_ >= argc_) return false;
    flag_ = argv_[index_];
    return true;
  }
  const std::string& flag() const { return flag_; }
  bool is(const char* name) const { return flag_ == name; }

  // The value that follows the current flag.
  std::string value() {
    if (index_ + 1 >= argc_) throw UsageError(flag_ + " needs a value");
    return argv_[++index_];
  }

  // The value that follows the current flag, read whole as a number of type T.
  template <typename T>
  T number() {
    return parseNumber<T>(flag_, value());
  }

  [[noreturn]] void rejectFlag() const { throw UsageError("unknown option '" + flag_ + "'"); }

 private:
  int argc_;
  char** argv_;
  int index_ = 0;
  std::string flag_;
};

// Runs `body()` (which returns the exit status): --help prints `usage`, a UsageError prints the message
// and the usage and exits 2, any other exception prints its message and exits 1.
template <typename Body>
int runTool(const char* name, const char* usage, int argc, char** argv, Body body) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::cout << usage;
      return 0;
    }
  }
  try {
    return body();
  } catch (const UsageError& error) {
    std::cerr << name << ": " << error.what() << "\n\n" << usage;
    return 2;
  } catch (const std::exception& error) {
    std::cerr << name << ": " << error.what() << '\n';
    return 1;
  }
}

}  // namespace elo::tools
