// Shared checks of the io tests.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <initializer_list>
#include <random>
#include <string>

#include "../text_contains.hpp"
#include "elo/io/io_error.hpp"
#include "elo/types.hpp"

namespace elo::test {

// Runs `action`, expecting an exception of type E whose message contains every one of `fragments`.
template <typename E>
void expectThrowContaining(const std::function<void()>& action, std::initializer_list<std::string> fragments) {
  try {
    action();
    ADD_FAILURE() << "expected an exception";
  } catch (const E& error) {
    for (const std::string& fragment : fragments) {
      EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos)
          << "message '" << error.what() << "' does not contain '" << fragment << "'";
    }
  }
}

// The message of the IoError `action` throws; empty when it throws none.
inline std::string errorOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const IoError& error) {
    return error.what();
  }
  return "";
}

inline void writeText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

inline PointCloud randomCloud(size_t count, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<float> coordinate(-80.0f, 80.0f);
  std::uniform_real_distribution<float> reflectance(0.0f, 1.0f);
  PointCloud cloud;
  for (size_t i = 0; i < count; ++i) {
    cloud.points.emplace_back(coordinate(generator), coordinate(generator), coordinate(generator));
    cloud.intensity.push_back(reflectance(generator));
  }
  return cloud;
}

inline void expectSamePoints(const PointCloud& expected, const PointCloud& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(expected.points[i], actual.points[i]) << "point " << i;
  }
  EXPECT_EQ(expected.intensity, actual.intensity);
}

}  // namespace elo::test
