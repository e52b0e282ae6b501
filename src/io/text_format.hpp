// Helpers the text readers and writers of elo_io share (not installed): opening files with errors
// that name them, and numbers read strictly and written without losing precision.
#pragma once

#include <cstddef>
#include <fstream>
#include <string>
#include <vector>

namespace elo::io_detail {

std::ifstream openForReading(const std::string& path, std::ios::openmode mode = std::ios::in);
std::ofstream openForWriting(const std::string& path, std::ios::openmode mode = std::ios::out);
// Flushes and throws IoError when any write to `path` failed (a full disk shows up only here).
void finishWriting(std::ofstream& stream, const std::string& path);

// The shortest text that reads back as the same double.
std::string formatDouble(double value);
// `values` formatted as above, separated by single spaces.
std::string formatDoubles(const std::vector<double>& values);

// The whitespace-separated numbers of `text`; throws IoError naming `path` and `line_number` at the
// first token that is not a number.
std::vector<double> parseNumbers(const std::string& text, const std::string& path, size_t line_number);

// Every non-blank line of a text stream as `columns` numbers; throws IoError naming `name` (the file)
// and the line of a row with another count or a token that is not a number.
std::vector<std::vector<double>> readNumberRows(std::istream& stream, const std::string& name, size_t columns);

}  // namespace elo::io_detail
