// The one exception type of the readers and writers: its message names the file and, for text files,
// the line, so that a user can fix the data without reading the code.
#pragma once

#include <stdexcept>

namespace elo {

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace elo
