#include "pcd_format.hpp"

#include <pcl/io/lzf.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <type_traits>

#include "elo/io/io_error.hpp"

namespace elo::io_detail {
namespace {

using pcl::PCLPointField;

enum class Encoding { ascii, binary, binary_compressed };

// The header's lines as written, before they are checked against each other.
struct HeaderLines {
  std::vector<std::string> names, sizes, types, counts;
  std::optional<uint32_t> width, height;
  std::optional<uint64_t> points;
  Encoding encoding = Encoding::ascii;
  size_t data_offset = 0;      // the first byte after the DATA line
  size_t first_data_line = 0;  // its line number, for messages about ascii points
};

// The checked header: every field has a PCD type, and the point count is consistent.
struct Header {
  std::vector<PCLPointField> fields;
  size_t point_step = 0;
  size_t count = 0;
  Encoding encoding = Encoding::ascii;
  size_t data_offset = 0;
  size_t first_data_line = 0;
};

// LZF encodes at most 264 bytes in a 3-byte back reference, so no valid stream expands more than this.
constexpr uint64_t kMaxLzfExpansion = 88;

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw IoError("cannot read '" + path + "': " + problem);
}

[[noreturn]] void failAtLine(const std::string& path, size_t line_number, const std::string& problem) {
  throw IoError(path + ":" + std::to_string(line_number) + ": " + problem);
}

std::vector<std::string> splitWords(const std::string& line) {
  std::vector<std::string> words;
  size_t begin = line.find_first_not_of(" \t\r");
  while (begin != std::string::npos) {
    const size_t end = line.find_first_of(" \t\r", begin);
    words.push_back(line.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
    begin = line.find_first_not_of(" \t\r", end);
  }
  return words;
}

// The whole word as an integer of type T: no sign where T has none, nothing left over, no overflow.
template <typename T>
std::optional<T> parseInteger(const std::string& word) {
  T value{};
  const char* end = word.data() + word.size();
  const auto result = std::from_chars(word.data(), end, value);
  if (result.ec != std::errc() || result.ptr != end) return std::nullopt;
  return value;
}

template <typename T>
T headerNumber(const std::vector<std::string>& values, const std::string& keyword, const std::string& path,
               size_t line_number) {
  const std::optional<T> value = values.size() == 1 ? parseInteger<T>(values[0]) : std::nullopt;
  if (!value) failAtLine(path, line_number, keyword + " needs one whole number in range");
  return *value;
}

Encoding parseEncoding(const std::vector<std::string>& values, const std::string& path, size_t line_number) {
  const std::string kind = values.empty() ? "" : values[0];
  if (kind == "ascii") return Encoding::ascii;
  if (kind == "binary") return Encoding::binary;
  if (kind == "binary_compressed") return Encoding::binary_compressed;
  failAtLine(path, line_number, "DATA '" + kind + "' is none of ascii, binary, binary_compressed");
}

void readHeaderLine(const std::string& keyword, const std::vector<std::string>& values, HeaderLines& lines,
                    const std::string& path, size_t line_number) {
  if (keyword == "VERSION" || keyword == "VIEWPOINT") return;  // nothing a scan needs
  if (keyword == "FIELDS" || keyword == "COLUMNS") {
    lines.names = values;
  } else if (keyword == "SIZE") {
    lines.sizes = values;
  } else if (keyword == "TYPE") {
    lines.types = values;
  } else if (keyword == "COUNT") {
    lines.counts = values;
  } else if (keyword == "WIDTH") {
    lines.width = headerNumber<uint32_t>(values, keyword, path, line_number);
  } else if (keyword == "HEIGHT") {
    lines.height = headerNumber<uint32_t>(values, keyword, path, line_number);
  } else if (keyword == "POINTS") {
    lines.points = headerNumber<uint64_t>(values, keyword, path, line_number);
  } else {
    failAtLine(path, line_number, "not a PCD file: '" + keyword + "' is not a PCD header keyword");
  }
}

// The header ends with its DATA line; comments (#) and blank lines may come anywhere before it.
HeaderLines readHeaderLines(const std::string& bytes, const std::string& path) {
  HeaderLines lines;
  size_t begin = 0;
  for (size_t line_number = 1; begin < bytes.size(); ++line_number) {
    const size_t newline = bytes.find('\n', begin);
    const size_t end = newline == std::string::npos ? bytes.size() : newline;
    const std::vector<std::string> words = splitWords(bytes.substr(begin, end - begin));
    begin = end + 1;
    if (words.empty() || words[0][0] == '#') continue;
    const std::vector<std::string> values(words.begin() + 1, words.end());
    if (words[0] == "DATA") {
      lines.encoding = parseEncoding(values, path, line_number);
      lines.data_offset = std::min(begin, bytes.size());
      lines.first_data_line = line_number + 1;
      return lines;
    }
    readHeaderLine(words[0], values, lines, path, line_number);
  }
  fail(path, "not a PCD file (no DATA line)");
}

// The PCL datatype of a PCD TYPE letter with a SIZE; 0 for a pair that names none.
uint8_t datatypeOf(const std::string& type, uint64_t size) {
  if (type == "I" && size == 1) return PCLPointField::INT8;
  if (type == "I" && size == 2) return PCLPointField::INT16;
  if (type == "I" && size == 4) return PCLPointField::INT32;
  if (type == "I" && size == 8) return kPcdInt64;
  if (type == "U" && size == 1) return PCLPointField::UINT8;
  if (type == "U" && size == 2) return PCLPointField::UINT16;
  if (type == "U" && size == 4) return PCLPointField::UINT32;
  if (type == "U" && size == 8) return kPcdUint64;
  if (type == "F" && size == 4) return PCLPointField::FLOAT32;
  if (type == "F" && size == 8) return PCLPointField::FLOAT64;
  return 0;
}

size_t datatypeSize(uint8_t datatype) {
  switch (datatype) {
    case PCLPointField::INT8:
    case PCLPointField::UINT8: return 1;
    case PCLPointField::INT16:
    case PCLPointField::UINT16: return 2;
    case PCLPointField::INT32:
    case PCLPointField::UINT32:
    case PCLPointField::FLOAT32: return 4;
    default: return 8;  // INT64, UINT64, FLOAT64: buildFields admits no other type
  }
}

void checkValueCount(const std::vector<std::string>& values, size_t fields, const char* keyword,
                     const std::string& path) {
  if (values.size() != fields) {
    fail(path, std::string(keyword) + " has " + std::to_string(values.size()) + " values for " +
                   std::to_string(fields) + " FIELDS");
  }
}

// Fields packed one after another, as PCD lays them out; the offset of the next one is the point size.
std::vector<PCLPointField> buildFields(const HeaderLines& lines, size_t& point_step, const std::string& path) {
  const size_t field_count = lines.names.size();
  if (field_count == 0) fail(path, "not a PCD file (no FIELDS line)");
  checkValueCount(lines.sizes, field_count, "SIZE", path);
  checkValueCount(lines.types, field_count, "TYPE", path);
  if (!lines.counts.empty()) checkValueCount(lines.counts, field_count, "COUNT", path);
  std::vector<PCLPointField> fields(field_count);
  uint64_t offset = 0;
  for (size_t i = 0; i < field_count; ++i) {
    const std::optional<uint8_t> size = parseInteger<uint8_t>(lines.sizes[i]);
    const std::optional<uint32_t> count = lines.counts.empty() ? 1u : parseInteger<uint32_t>(lines.counts[i]);
    const uint8_t datatype = size ? datatypeOf(lines.types[i], *size) : 0;
    if (datatype == 0 || !count || *count == 0) {
      fail(path, "field '" + lines.names[i] + "' has TYPE " + lines.types[i] + ", SIZE " + lines.sizes[i] +
                     (lines.counts.empty() ? "" : ", COUNT " + lines.counts[i]) + ": not a PCD field type");
    }
    fields[i].name = lines.names[i];
    fields[i].offset = static_cast<uint32_t>(offset);
    fields[i].datatype = datatype;
    fields[i].count = *count;
    offset += static_cast<uint64_t>(*size) * *count;
    if (offset > std::numeric_limits<uint32_t>::max()) fail(path, "a point is larger than 4 GB");
  }
  point_step = static_cast<size_t>(offset);
  return fields;
}

// WIDTH x HEIGHT, which must agree with POINTS. Old files may give only POINTS (PCL reads them so).
size_t pointCount(const HeaderLines& lines, const std::string& path) {
  if (!lines.width && !lines.height) {
    if (!lines.points) fail(path, "the header gives neither WIDTH nor POINTS");
    return static_cast<size_t>(*lines.points);
  }
  if (!lines.width) fail(path, "the header gives HEIGHT without WIDTH");
  const uint64_t count = static_cast<uint64_t>(*lines.width) * lines.height.value_or(1);
  if (lines.points && *lines.points != count) {
    fail(path, "WIDTH x HEIGHT is " + std::to_string(count) + " but POINTS is " + std::to_string(*lines.points));
  }
  return static_cast<size_t>(count);
}

Header parseHeader(const std::string& bytes, const std::string& path) {
  const HeaderLines lines = readHeaderLines(bytes, path);
  Header header;
  header.fields = buildFields(lines, header.point_step, path);
  header.count = pointCount(lines, path);
  header.encoding = lines.encoding;
  header.data_offset = lines.data_offset;
  header.first_data_line = lines.first_data_line;
  return header;
}

std::vector<uint8_t> readBinaryPoints(const std::string& bytes, const Header& header, const std::string& path) {
  const size_t available = bytes.size() - header.data_offset;
  if (available / header.point_step < header.count) {
    fail(path, "truncated: " + std::to_string(available) + " bytes of points, " + std::to_string(header.count) +
                   " points of " + std::to_string(header.point_step) + " bytes declared");
  }
  const auto* begin = reinterpret_cast<const uint8_t*>(bytes.data()) + header.data_offset;
  return std::vector<uint8_t>(begin, begin + header.count * header.point_step);
}

uint32_t readUint32(const std::string& bytes, size_t offset) {
  uint32_t value = 0;
  std::memcpy(&value, bytes.data() + offset, sizeof(value));
  return value;
}

// PCL's binary_compressed: compressed and uncompressed sizes (uint32), then the LZF-compressed fields
// one after another (all x, then all y, ...), without the `_` padding fields.
std::vector<uint8_t> readCompressedPoints(const std::string& bytes, const Header& header, const std::string& path) {
  const size_t available = bytes.size() - header.data_offset;
  if (available < 8) fail(path, "truncated: no compressed sizes after DATA binary_compressed");
  const uint32_t compressed_size = readUint32(bytes, header.data_offset);
  const uint32_t uncompressed_size = readUint32(bytes, header.data_offset + 4);
  uint64_t packed_point_step = 0;
  for (const PCLPointField& field : header.fields) {
    if (field.name != "_") packed_point_step += datatypeSize(field.datatype) * uint64_t{field.count};
  }
  if (compressed_size > available - 8) {
    fail(path, "truncated: " + std::to_string(compressed_size) + " compressed bytes declared, " +
                   std::to_string(available - 8) + " present");
  }
  // Checked before the allocation, which the header's counts size.
  if (uncompressed_size != packed_point_step * header.count ||
      uncompressed_size > kMaxLzfExpansion * compressed_size) {
    fail(path, "compressed points claim " + std::to_string(uncompressed_size) + " bytes; the header needs " +
                   std::to_string(packed_point_step * header.count) + " from " + std::to_string(compressed_size));
  }
  std::vector<uint8_t> fields_in_blocks(uncompressed_size);
  if (uncompressed_size > 0 &&
      pcl::lzfDecompress(bytes.data() + header.data_offset + 8, compressed_size, fields_in_blocks.data(),
                         uncompressed_size) != uncompressed_size) {
    fail(path, "the compressed points are corrupt (LZF decompression failed)");
  }
  std::vector<uint8_t> points(header.count * header.point_step);
  const uint8_t* block = fields_in_blocks.data();
  for (const PCLPointField& field : header.fields) {
    if (field.name == "_") continue;
    const size_t field_bytes = datatypeSize(field.datatype) * size_t{field.count};
    for (size_t i = 0; i < header.count; ++i, block += field_bytes) {
      std::memcpy(points.data() + i * header.point_step + field.offset, block, field_bytes);
    }
  }
  return points;
}

// One ascii value into `destination` as type T; false when the word is not such a value.
template <typename T>
bool storeWord(const std::string& word, uint8_t* destination) {
  T value{};
  if constexpr (std::is_floating_point_v<T>) {
    char* end = nullptr;  // strtod, which also reads the nan and inf PCL writes for missing returns
    const double parsed = std::strtod(word.c_str(), &end);
    if (word.empty() || end != word.c_str() + word.size()) return false;
    value = static_cast<T>(parsed);
  } else {
    const std::optional<T> parsed = parseInteger<T>(word);
    if (!parsed) return false;
    value = *parsed;
  }
  std::memcpy(destination, &value, sizeof(T));
  return true;
}

bool storeWord(const std::string& word, uint8_t datatype, uint8_t* destination) {
  switch (datatype) {
    case PCLPointField::INT8: return storeWord<int8_t>(word, destination);
    case PCLPointField::INT16: return storeWord<int16_t>(word, destination);
    case PCLPointField::INT32: return storeWord<int32_t>(word, destination);
    case kPcdInt64: return storeWord<int64_t>(word, destination);
    case PCLPointField::UINT8: return storeWord<uint8_t>(word, destination);
    case PCLPointField::UINT16: return storeWord<uint16_t>(word, destination);
    case PCLPointField::UINT32: return storeWord<uint32_t>(word, destination);
    case kPcdUint64: return storeWord<uint64_t>(word, destination);
    case PCLPointField::FLOAT32: return storeWord<float>(word, destination);
    default: return storeWord<double>(word, destination);  // buildFields admits no other type
  }
}

void storeAsciiPoint(const std::vector<std::string>& words, const Header& header, uint8_t* point,
                     const std::string& path, size_t line_number) {
  size_t word = 0;
  for (const PCLPointField& field : header.fields) {
    const size_t value_size = datatypeSize(field.datatype);
    for (uint32_t element = 0; element < field.count; ++element, ++word) {
      if (!storeWord(words[word], field.datatype, point + field.offset + element * value_size)) {
        failAtLine(path, line_number, "'" + words[word] + "' is not a valid value for field '" + field.name + "'");
      }
    }
  }
}

// One point a line, each field's values in order. The points grow with the lines actually present,
// so a large POINTS in a short file allocates nothing.
std::vector<uint8_t> readAsciiPoints(const std::string& bytes, const Header& header, const std::string& path) {
  size_t values_per_point = 0;
  for (const PCLPointField& field : header.fields) values_per_point += field.count;
  std::vector<uint8_t> points;
  size_t read = 0;
  size_t begin = header.data_offset;
  for (size_t line_number = header.first_data_line; begin < bytes.size(); ++line_number) {
    const size_t newline = bytes.find('\n', begin);
    const size_t end = newline == std::string::npos ? bytes.size() : newline;
    const std::vector<std::string> words = splitWords(bytes.substr(begin, end - begin));
    begin = end + 1;
    if (words.empty()) continue;
    if (read == header.count) {
      failAtLine(path, line_number, "more points than the " + std::to_string(read) + " declared");
    }
    if (words.size() != values_per_point) {
      failAtLine(path, line_number, std::to_string(words.size()) + " values, expected " +
                                        std::to_string(values_per_point));
    }
    points.resize((read + 1) * header.point_step);
    storeAsciiPoint(words, header, points.data() + read * header.point_step, path, line_number);
    ++read;
  }
  if (read != header.count) {
    fail(path, "truncated: " + std::to_string(read) + " of " + std::to_string(header.count) + " points present");
  }
  return points;
}

}  // namespace

PcdPoints parsePcd(const std::string& bytes, const std::string& path) {
  const Header header = parseHeader(bytes, path);
  PcdPoints result;
  result.fields = header.fields;
  result.point_step = header.point_step;
  result.count = header.count;
  switch (header.encoding) {
    case Encoding::ascii: result.data = readAsciiPoints(bytes, header, path); break;
    case Encoding::binary: result.data = readBinaryPoints(bytes, header, path); break;
    case Encoding::binary_compressed: result.data = readCompressedPoints(bytes, header, path); break;
  }
  return result;
}

}  // namespace elo::io_detail
