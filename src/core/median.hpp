// The median of a handful of values, as the core's checks take it (the upper one of an even count).
#pragma once

#include <algorithm>
#include <vector>

namespace elo {

// `values` must not be empty; taken by value, as nth_element reorders them.
template <typename T>
T upperMedian(std::vector<T> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

}  // namespace elo
