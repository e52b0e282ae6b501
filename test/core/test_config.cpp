#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <utility>

#include "elo/config.hpp"

namespace elo {
namespace {

TEST(Config, EveryParameterHasAUniqueDottedKeyAndADescription) {
  Config config;
  std::set<std::string> keys;
  for (const Parameter& parameter : parameters(config)) {
    EXPECT_TRUE(keys.insert(parameter.key).second) << "duplicate key " << parameter.key;
    EXPECT_NE(parameter.key.find('.'), std::string::npos) << parameter.key;
    EXPECT_FALSE(parameter.description.empty()) << parameter.key;
  }
  EXPECT_GE(keys.size(), 40u);
}

TEST(Config, DefaultsAreThePapersValues) {
  const Config config;
  EXPECT_EQ(config.sensor.image_width, 2048);
  EXPECT_EQ(config.sensor.image_height, 80);
  EXPECT_DOUBLE_EQ(config.ground.band_above, 0.5);
  EXPECT_DOUBLE_EQ(config.ground.band_below, 1.0);
  EXPECT_DOUBLE_EQ(config.ground.max_slope_deg, 5.0);
  EXPECT_DOUBLE_EQ(config.normals.search_size, 0.3);
  EXPECT_EQ(config.normals.min_window_width, 5);
  EXPECT_EQ(config.normals.max_window_width, 13);
  EXPECT_EQ(config.normals.min_window_height, 3);
  EXPECT_EQ(config.normals.max_window_height, 7);
  EXPECT_DOUBLE_EQ(config.normals.outlier_distance, 0.5);
  EXPECT_DOUBLE_EQ(config.normals.plane_distance, 0.5);
  EXPECT_DOUBLE_EQ(config.bev.cell_size, 0.1);
  EXPECT_DOUBLE_EQ(config.bev.half_length, 120.0);
  EXPECT_DOUBLE_EQ(config.bev.half_width, 60.0);
  EXPECT_EQ(config.bev.normal_neighbours, 5);
  EXPECT_DOUBLE_EQ(config.registration.nonground_weight, 0.7);
  EXPECT_DOUBLE_EQ(config.model.time_window, 10.0);
  EXPECT_EQ(config.sensor.beam_elevations_deg.size(), 64u);
  EXPECT_NO_THROW(validate(config));
}

TEST(Config, SetAndGetRoundTripThroughTheTable) {
  Config config;
  for (const Parameter& parameter : parameters(config)) {
    if (parameter.key == "model.mode") setFromString(parameter, "frame_to_frame");
    if (parameter.key == "ground.max_slope_deg") setFromString(parameter, "7.5");
    if (parameter.key == "registration.max_iterations") setFromString(parameter, "12");
    if (parameter.key == "sensor.beam_elevations_deg") setFromString(parameter, "1,0,-1");
  }
  EXPECT_EQ(config.model.mode, RegistrationMode::frame_to_frame);
  EXPECT_DOUBLE_EQ(config.ground.max_slope_deg, 7.5);
  EXPECT_EQ(config.registration.max_iterations, 12);
  EXPECT_EQ(config.sensor.beam_elevations_deg, (std::vector<double>{1, 0, -1}));
}

TEST(Config, WrongTypesAndChoicesNameTheParameter) {
  Config config;
  for (const Parameter& parameter : parameters(config)) {
    if (parameter.key == "model.mode") {
      try {
        setFromString(parameter, "sideways");
        FAIL() << "accepted an unknown choice";
      } catch (const ConfigError& error) {
        EXPECT_NE(std::string(error.what()).find("model.mode"), std::string::npos);
        EXPECT_NE(std::string(error.what()).find("frame_to_model"), std::string::npos);
      }
    }
    if (parameter.key == "sensor.image_width") {
      EXPECT_THROW(setFromString(parameter, "wide"), ConfigError);
      EXPECT_THROW(parameter.set(ParameterValue(std::string("12"))), ConfigError);
    }
  }
}

TEST(Config, ValidateNamesTheImpossibleParameter) {
  const auto message_of = [](const Config& config) {
    try {
      validate(config);
    } catch (const ConfigError& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  Config config;
  config.normals.max_window_width = 12;
  EXPECT_NE(message_of(config).find("normals.max_window_width"), std::string::npos);
  config = Config();
  config.sensor.fov_up_deg = -30.0;
  EXPECT_NE(message_of(config).find("sensor.fov_up_deg"), std::string::npos);
  config = Config();
  config.sensor.beam_count = 32;
  EXPECT_NE(message_of(config).find("sensor.beam_elevations_deg"), std::string::npos);
  config = Config();
  std::swap(config.sensor.beam_elevations_deg[3], config.sensor.beam_elevations_deg[4]);  // rings would miss
  EXPECT_NE(message_of(config).find("must run from the top beam down"), std::string::npos);
  config.sensor.ring_zero = RingZero::table;  // the driver's own order
  EXPECT_EQ(message_of(config), "accepted");
  config.sensor.beam_elevations_deg.clear();
  EXPECT_NE(message_of(config).find("sensor.ring_zero"), std::string::npos);
  config = Config();
  config.bev.cell_size = 0.001;
  EXPECT_NE(message_of(config).find("bev.cell_size"), std::string::npos);
  config = Config();
  config.ground.rise_tolerance = -0.01;
  EXPECT_NE(message_of(config).find("ground.rise_tolerance"), std::string::npos);
  config = Config();
  config.registration.association_radius = config.sensor.image_width / 2 + 1;  // would visit columns twice
  EXPECT_NE(message_of(config).find("registration.association_radius"), std::string::npos);
  config = Config();
  config.registration.near_weight_range = -1.0;
  EXPECT_NE(message_of(config).find("registration.near_weight_range"), std::string::npos);
}

TEST(Config, DeskewKeysSetTheTimeSourceAndTheSweep) {
  Config config;
  EXPECT_EQ(config.deskew.time_source, TimeSource::field);
  EXPECT_TRUE(config.sensor.clockwise);
  EXPECT_DOUBLE_EQ(config.sensor.sweep_start_azimuth_deg, 180.0);
  for (const Parameter& parameter : parameters(config)) {
    if (parameter.key == "deskew.time_source") {
      setFromString(parameter, "azimuth");
      EXPECT_THROW(setFromString(parameter, "lidar"), ConfigError);
    }
    if (parameter.key == "deskew.rounds") setFromString(parameter, "2");
    if (parameter.key == "sensor.clockwise") setFromString(parameter, "false");
    if (parameter.key == "sensor.sweep_start_azimuth_deg") setFromString(parameter, "90");
  }
  EXPECT_EQ(config.deskew.time_source, TimeSource::azimuth);
  EXPECT_EQ(config.deskew.rounds, 2);
  EXPECT_FALSE(config.sensor.clockwise);
  EXPECT_DOUBLE_EQ(config.sensor.sweep_start_azimuth_deg, 90.0);
  config.deskew.rounds = -1;
  EXPECT_THROW(validate(config), ConfigError);
}

// The README keeps the few parameters a user is likely to set and links docs/parameters.md for all.
TEST(Config, EveryParameterIsDocumentedInTheParameterReference) {
  std::ifstream file(std::string(ELO_SOURCE_DIR) + "/docs/parameters.md");
  ASSERT_TRUE(file) << "docs/parameters.md not found";
  std::stringstream text;
  text << file.rdbuf();
  const std::string reference = text.str();
  const size_t table = reference.find("## Odometry");
  ASSERT_NE(table, std::string::npos);
  Config config;
  for (const Parameter& parameter : parameters(config)) {
    const std::string name = parameter.key.substr(parameter.key.find('.') + 1);
    EXPECT_NE(reference.find(name + "`", table), std::string::npos)
        << parameter.key << " is missing from docs/parameters.md";
  }
}

}  // namespace
}  // namespace elo
