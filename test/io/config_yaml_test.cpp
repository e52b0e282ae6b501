#include "elo/io/config_yaml.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "elo/io/io_error.hpp"
#include "temp_directory.hpp"
#include "test_helpers.hpp"

namespace elo {
namespace {

namespace fs = std::filesystem;
using test::expectThrowContaining;
using test::TempDirectory;

// Writes `yaml` to a file in `directory` and loads it into `config`.
void loadText(const TempDirectory& directory, const std::string& yaml, Config& config) {
  const std::string path = directory.file("config.yaml");
  test::writeText(path, yaml);
  loadConfigYaml(path, config);
}

TEST(ConfigYaml, NestedKeysSetTheirParameters) {
  TempDirectory directory;
  Config config;
  loadText(directory,
           "ground:\n"
           "  max_slope_deg: 7.5\n"
           "sensor: {image_width: 1024, name: vlp64}\n"
           "registration:\n"
           "  terms: bev_ground\n",
           config);
  EXPECT_EQ(config.ground.max_slope_deg, 7.5);
  EXPECT_EQ(config.sensor.image_width, 1024);
  EXPECT_EQ(config.sensor.name, "vlp64");
  EXPECT_EQ(config.registration.terms, CostTerms::bev_ground);
  EXPECT_EQ(config.ground.sensor_height, Config().ground.sensor_height);  // untouched keys keep their default
}

TEST(ConfigYaml, SequenceSetsAListOfNumbers) {
  TempDirectory directory;
  Config config;
  std::vector<double> elevations = config.sensor.beam_elevations_deg;
  std::string yaml = "sensor:\n  beam_elevations_deg: [";
  for (size_t i = 0; i < elevations.size(); ++i) {
    elevations[i] *= 0.5;
    yaml += (i == 0 ? "" : ", ") + std::to_string(elevations[i]);
  }
  loadText(directory, yaml + "]\n", config);
  ASSERT_EQ(config.sensor.beam_elevations_deg.size(), elevations.size());
  for (size_t i = 0; i < elevations.size(); ++i) {
    EXPECT_NEAR(config.sensor.beam_elevations_deg[i], elevations[i], 1e-6);
  }
}

TEST(ConfigYaml, IntegerWrittenForADoubleIsAccepted) {
  TempDirectory directory;
  Config config;
  loadText(directory, "ground:\n  max_slope_deg: 4\n", config);
  EXPECT_EQ(config.ground.max_slope_deg, 4.0);
}

TEST(ConfigYaml, EmptyFileKeepsTheDefaults) {
  TempDirectory directory;
  Config config;
  loadText(directory, "# nothing set\n", config);
  EXPECT_EQ(dumpConfigYaml(config), dumpConfigYaml(Config()));
}

TEST(ConfigYaml, UnknownKeyThrowsNamingTheKeyAndFile) {
  TempDirectory directory;
  Config config;
  expectThrowContaining<ConfigError>([&] { loadText(directory, "ground:\n  max_slop_deg: 5\n", config); },
                                     {"ground.max_slop_deg", directory.file("config.yaml") + ":2", "unknown"});
  expectThrowContaining<ConfigError>([&] { loadText(directory, "grund: {max_slope_deg: 5}\n", config); },
                                     {"grund.max_slope_deg"});
}

TEST(ConfigYaml, WrongTypeThrowsNamingTheKey) {
  TempDirectory directory;
  Config config;
  expectThrowContaining<ConfigError>([&] { loadText(directory, "sensor:\n  image_width: wide\n", config); },
                                     {"sensor.image_width", "integer", directory.file("config.yaml") + ":2"});
  expectThrowContaining<ConfigError>([&] { loadText(directory, "sensor: {image_width: 5.5}\n", config); },
                                     {"sensor.image_width"});
  expectThrowContaining<ConfigError>([&] { loadText(directory, "ground: {max_slope_deg: [1, 2]}\n", config); },
                                     {"ground.max_slope_deg", "a number"});
  expectThrowContaining<ConfigError>([&] { loadText(directory, "sensor: {beam_elevations_deg: 3}\n", config); },
                                     {"sensor.beam_elevations_deg", "sequence"});
  expectThrowContaining<ConfigError>([&] { loadText(directory, "ground: {max_slope_deg: {deg: 3}}\n", config); },
                                     {"ground.max_slope_deg"});
  expectThrowContaining<ConfigError>([&] { loadText(directory, "ground: {max_slope_deg: }\n", config); },
                                     {"ground.max_slope_deg"});
}

// yaml-cpp throws its own exception for these; the loader names the parameter instead (found by fuzzing).
TEST(ConfigYaml, MalformedSequenceAndKeyThrowNamingTheParameter) {
  TempDirectory directory;
  Config config;
  expectThrowContaining<ConfigError>([&] { loadText(directory, "sensor: {beam_elevations_deg: [2, 0x]}\n", config); },
                                     {"sensor.beam_elevations_deg", "sequence of numbers"});
  expectThrowContaining<ConfigError>([&] { loadText(directory, "sensor: {[image_width]: 5}\n", config); },
                                     {directory.file("config.yaml") + ":1", "parameter or section name"});
}

TEST(ConfigYaml, LoadsFromAStream) {
  std::istringstream stream("ground:\n  max_slope_deg: 4.5\n");
  Config config;
  loadConfigYaml(stream, "memory", config);
  EXPECT_EQ(config.ground.max_slope_deg, 4.5);
}

TEST(ConfigYaml, UnknownChoiceThrows) {
  TempDirectory directory;
  Config config;
  expectThrowContaining<ConfigError>([&] { loadText(directory, "registration: {terms: fusion}\n", config); },
                                     {directory.file("config.yaml")});
}

TEST(ConfigYaml, ValuesThatCannotWorkFailValidation) {
  TempDirectory directory;
  Config config;
  expectThrowContaining<ConfigError>([&] { loadText(directory, "sensor: {image_width: 0}\n", config); },
                                     {directory.file("config.yaml")});
}

TEST(ConfigYaml, InvalidYamlThrowsNamingTheFileAndLine) {
  TempDirectory directory;
  Config config;
  expectThrowContaining<IoError>([&] { loadText(directory, "ground:\n  max_slope_deg: [1, 2\n", config); },
                                 {directory.file("config.yaml") + ":"});
  expectThrowContaining<IoError>([&] { loadConfigYaml("/nonexistent/config.yaml", config); },
                                 {"/nonexistent/config.yaml"});
}

TEST(ConfigYaml, DumpRoundTrips) {
  TempDirectory directory;
  Config config;
  config.ground.max_slope_deg = 3.3;
  config.sensor.name = "true";  // a string that YAML would read as a boolean unless typed by the parameter
  config.registration.terms = CostTerms::spherical_all;
  config.normals.min_neighbours = 7;
  config.sensor.beam_elevations_deg = {1.0 / 3.0, -0.1, -24.9};
  config.sensor.beam_count = 3;
  const std::string dump = dumpConfigYaml(config);

  Config loaded;
  loadText(directory, dump, loaded);
  EXPECT_EQ(dumpConfigYaml(loaded), dump);
  EXPECT_EQ(loaded.ground.max_slope_deg, 3.3);
  EXPECT_EQ(loaded.sensor.name, "true");
  EXPECT_EQ(loaded.registration.terms, CostTerms::spherical_all);
  EXPECT_EQ(loaded.normals.min_neighbours, 7);
  EXPECT_EQ(loaded.sensor.beam_elevations_deg, config.sensor.beam_elevations_deg);
}

TEST(ConfigYaml, DumpNestsEveryParameterWithItsDescription) {
  Config config;
  const std::string dump = dumpConfigYaml(config);
  EXPECT_NE(dump.find("ground:\n  "), std::string::npos) << dump;
  EXPECT_NE(dump.find("max_slope_deg: 5"), std::string::npos) << dump;
  for (const Parameter& parameter : parameters(config)) {
    EXPECT_NE(dump.find("# " + parameter.description), std::string::npos) << parameter.key;
    for (const std::string& choice : parameter.choices) {
      EXPECT_NE(dump.find(choice), std::string::npos) << parameter.key << " choice " << choice;
    }
  }
}

TEST(ConfigYaml, EveryShippedConfigLoads) {
  const fs::path directory = fs::path(ELO_SOURCE_DIR) / "config";
  if (!fs::is_directory(directory)) {
    GTEST_SKIP() << "no config directory at " << directory;
  }
  size_t loaded = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory)) {
    if (entry.path().extension() == ".yaml") {
      Config config;
      try {
        loadConfigYaml(entry.path().string(), config);
      } catch (const std::exception& error) {
        ADD_FAILURE() << error.what();
      }
      ++loaded;
    }
  }
  if (loaded == 0) {
    GTEST_SKIP() << "no .yaml file in " << directory;
  }
}

}  // namespace
}  // namespace elo
