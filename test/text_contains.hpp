// Whether a text (a tool's output, an error's message) holds a fragment: the tests' checks of messages.
#pragma once

#include <string>

namespace elo::test {

inline bool contains(const std::string& text, const std::string& fragment) {
  return text.find(fragment) != std::string::npos;
}

}  // namespace elo::test
