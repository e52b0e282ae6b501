#include "text_format.hpp"

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>

#include "elo/io/io_error.hpp"

namespace elo::io_detail {

std::ifstream openForReading(const std::string& path, std::ios::openmode mode) {
  std::ifstream stream(path, mode);
  if (!stream) {
    throw IoError("cannot open '" + path + "' for reading: " + std::strerror(errno));
  }
  return stream;
}

std::ofstream openForWriting(const std::string& path, std::ios::openmode mode) {
  std::ofstream stream(path, mode);
  if (!stream) {
    throw IoError("cannot open '" + path + "' for writing: " + std::strerror(errno));
  }
  return stream;
}

void finishWriting(std::ofstream& stream, const std::string& path) {
  stream.flush();
  if (!stream) {
    throw IoError("writing '" + path + "' failed: " + std::strerror(errno));
  }
}

// std::to_chars for double comes with libstdc++ 11 (__cpp_lib_to_chars); GCC 9 and 10 (Noetic, Debian 11)
// have it for integers only. There the shortest %g precision that reads back as the same double does:
// the same digits, though where the exponent starts may differ.
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L
std::string formatDouble(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}
#else
std::string formatDouble(double value) {
  char buffer[32];
  for (int precision = 1;; ++precision) {
    std::snprintf(buffer, sizeof(buffer), "%.*g", precision, value);
    if (precision == std::numeric_limits<double>::max_digits10 || std::strtod(buffer, nullptr) == value) break;
  }
  return buffer;
}
#endif

std::string formatDoubles(const std::vector<double>& values) {
  std::string text;
  for (double value : values) {
    if (!text.empty()) {
      text += ' ';
    }
    text += formatDouble(value);
  }
  return text;
}

std::vector<double> parseNumbers(const std::string& text, const std::string& path, size_t line_number) {
  std::vector<double> numbers;
  std::istringstream tokens(text);
  std::string token;
  while (tokens >> token) {
    // strtod rather than from_chars: it also accepts the "+1.0e+00" and "inf" some writers produce.
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size()) {
      throw IoError(path + ":" + std::to_string(line_number) + ": '" + token + "' is not a number");
    }
    numbers.push_back(value);
  }
  return numbers;
}

std::vector<std::vector<double>> readNumberRows(std::istream& stream, const std::string& name, size_t columns) {
  std::vector<std::vector<double>> rows;
  std::string line;
  for (size_t line_number = 1; std::getline(stream, line); ++line_number) {
    std::vector<double> numbers = parseNumbers(line, name, line_number);
    if (numbers.empty()) {
      continue;  // blank lines, such as a trailing one, carry no frame
    }
    if (numbers.size() != columns) {
      throw IoError(name + ":" + std::to_string(line_number) + ": expected " + std::to_string(columns) +
                    " numbers, found " + std::to_string(numbers.size()));
    }
    rows.push_back(std::move(numbers));
  }
  return rows;
}

}  // namespace elo::io_detail
