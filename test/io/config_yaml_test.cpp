#include "elo/io/config_yaml.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <vector>

#include "elo/io/io_error.hpp"
#include "elo/sensor/projections.hpp"
#include "elo/sensor/sensor_fit.hpp"
#include "elo/sensor/sensor_model.hpp"
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

// The .yaml files in config/ and its platforms/ (none when the tree is absent).
std::vector<fs::path> shippedConfigs() {
  std::vector<fs::path> files;
  const fs::path directory = fs::path(ELO_SOURCE_DIR) / "config";
  if (!fs::is_directory(directory)) return files;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(directory)) {
    if (entry.path().extension() == ".yaml") files.push_back(entry.path());
  }
  return files;
}

TEST(ConfigYaml, EveryShippedConfigLoads) {
  const std::vector<fs::path> files = shippedConfigs();
  if (files.empty()) GTEST_SKIP() << "no .yaml file in " << ELO_SOURCE_DIR << "/config";
  for (const fs::path& file : files) {
    Config config;
    try {
      loadConfigYaml(file.string(), config);
    } catch (const std::exception& error) {
      ADD_FAILURE() << error.what();
    }
  }
}

// Every sensor's range image gives each beam a row of its own, inside the image and away from the row's
// edges, so that a point's row from its ring and from its elevation agree (docs/sensors.md). The tables'
// spacings are no multiple of a row: the tightest beams sit 0.003 deg inside theirs. The one exception
// is the paper's image, 80 rows of 0.35 deg over the HDL-64E (the defaults: hdl64.yaml, kitti.yaml),
// which is not laid out by beams: there beams 1/3 deg apart meet, near a row's edge.
TEST(ConfigYaml, EveryShippedSensorGivesEachBeamARowOfItsOwn) {
  constexpr double kMinInsideRowDeg = 0.002;
  const std::vector<fs::path> files = shippedConfigs();
  if (files.empty()) GTEST_SKIP() << "no .yaml file in " << ELO_SOURCE_DIR << "/config";
  for (const fs::path& file : files) {
    Config config;
    loadConfigYaml(file.string(), config);
    const bool papers_image = config.sensor.image_height == Config().sensor.image_height;
    const SphericalProjection projection = SphericalProjection::fromConfig(config.sensor);
    const double row_deg = (config.sensor.fov_up_deg - config.sensor.fov_down_deg) / config.sensor.image_height;
    std::map<int, float> beam_of_row;
    for (const float beam : beamElevations(config.sensor)) {
      const double beam_deg = beam * 180.0 / M_PI;
      const int row = projection.rowOfElevation(beam);
      EXPECT_GE(row, 0) << file.filename() << ": the beam at " << beam_deg << " deg";
      EXPECT_LT(row, config.sensor.image_height) << file.filename() << ": the beam at " << beam_deg << " deg";
      if (papers_image) continue;
      const double rows_down = (config.sensor.fov_up_deg - beam_deg) / row_deg;
      const double inside_deg = std::min(rows_down - std::floor(rows_down), std::ceil(rows_down) - rows_down) * row_deg;
      EXPECT_GE(inside_deg, kMinInsideRowDeg) << file.filename() << ": the beam at " << beam_deg << " deg";
      const auto [entry, inserted] = beam_of_row.emplace(row, beam);
      EXPECT_TRUE(inserted || entry->second == beam) << file.filename() << ": beams at " << entry->second * 180.0 / M_PI
                                                     << " and " << beam_deg << " deg share row " << row;
    }
  }
}

// Every sensor's normals reach kMinNormalReach: sensors with beams 1 to 2 deg apart set
// normals.outlier_distance 1.0 (the Bpearl's 2.8 deg 1.5), docs/accuracy.md.
TEST(ConfigYaml, EveryShippedSensorsNormalsReachFarEnough) {
  const std::vector<fs::path> files = shippedConfigs();
  if (files.empty()) GTEST_SKIP() << "no .yaml file in " << ELO_SOURCE_DIR << "/config";
  for (const fs::path& file : files) {
    Config config;
    loadConfigYaml(file.string(), config);
    EXPECT_EQ(normalReachWarning(config), "") << file.filename();
  }
}

}  // namespace
}  // namespace elo
