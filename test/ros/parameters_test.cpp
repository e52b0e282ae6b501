// ROS parameters -> elo::Config through elo::parameters(): the same keys as the YAML files, shortcuts,
// type errors and unknown keys. No ROS master: the trees are what the parameter server would return.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "elo/io/config_yaml.hpp"
#include "parameters.hpp"

namespace {

using XmlRpc::XmlRpcValue;

// A YAML scalar as rosparam loads it: booleans, integers, floats, else a string.
XmlRpcValue scalarToXmlRpc(const YAML::Node& node) {
  const std::string text = node.Scalar();
  if (text == "true" || text == "false") return XmlRpcValue(text == "true");
  try {
    size_t used = 0;
    const int integer = std::stoi(text, &used);
    if (used == text.size()) return XmlRpcValue(integer);
  } catch (const std::exception&) {
  }
  try {
    size_t used = 0;
    const double number = std::stod(text, &used);
    if (used == text.size()) return XmlRpcValue(number);
  } catch (const std::exception&) {
  }
  return XmlRpcValue(text);
}

XmlRpcValue yamlToXmlRpc(const YAML::Node& node) {
  XmlRpcValue value;
  if (node.IsMap()) {
    for (const auto& item : node) value[item.first.as<std::string>()] = yamlToXmlRpc(item.second);
  } else if (node.IsSequence()) {
    value.setSize(static_cast<int>(node.size()));
    for (size_t i = 0; i < node.size(); ++i) value[static_cast<int>(i)] = yamlToXmlRpc(node[i]);
  } else {
    value = scalarToXmlRpc(node);
  }
  return value;
}

XmlRpcValue tree(const std::string& yaml) { return yamlToXmlRpc(YAML::Load(yaml)); }

// Every parameter's value as text, to compare two configurations whole.
std::vector<std::string> describe(elo::Config config) {
  std::vector<std::string> values;
  for (const elo::Parameter& parameter : elo::parameters(config)) {
    values.push_back(parameter.key + "=" + elo::toString(parameter.get()));
  }
  return values;
}

TEST(RosParameters, NestedKeysSetTheTableParameters) {
  elo::Config config;
  const auto unknown = elo_ros::applyConfigParameters(
      tree("ground: {max_slope_deg: 7.5}\n"
           "sensor: {beam_elevations_deg: [2, -1.5, -5], beam_count: 3, name: vlp}\n"
           "normals: {method: eigen}\n"
           "registration: {max_correspondence_distance: 2}\n"  // an integer for a double
           "odom_frame: odom\n"),
      config);
  EXPECT_TRUE(unknown.empty());
  EXPECT_DOUBLE_EQ(config.ground.max_slope_deg, 7.5);
  EXPECT_EQ(config.sensor.beam_elevations_deg, (std::vector<double>{2, -1.5, -5}));
  EXPECT_EQ(config.sensor.beam_count, 3);
  EXPECT_EQ(config.sensor.name, "vlp");
  EXPECT_EQ(config.normals.method, elo::NormalMethod::eigen);
  EXPECT_DOUBLE_EQ(config.registration.max_correspondence_distance, 2.0);
}

// rosparam load of a config file and elo_run's --config of the same file give the same configuration.
TEST(RosParameters, EveryConfigFileMatchesLoadConfigYaml) {
  const std::filesystem::path directory = std::filesystem::path(ELO_SOURCE_DIR) / "config";
  size_t files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(directory)) {
    if (entry.path().extension() != ".yaml") continue;
    ++files;
    elo::Config from_yaml;
    elo::loadConfigYaml(entry.path().string(), from_yaml);
    elo::Config from_ros;
    EXPECT_TRUE(elo_ros::applyConfigParameters(yamlToXmlRpc(YAML::LoadFile(entry.path().string())), from_ros).empty());
    EXPECT_EQ(describe(from_ros), describe(from_yaml)) << entry.path();
  }
  EXPECT_GE(files, 5u);
}

TEST(RosParameters, ShortcutsWinOverNestedKeys) {
  elo::Config config;
  elo_ros::applyConfigParameters(
      tree("runtime: {threads: 4}\nthreads: 2\nbackend: cpu\nmode: f2f\nmodel: {mode: frame_to_model}"), config);
  EXPECT_EQ(config.runtime.threads, 2);
  EXPECT_EQ(config.runtime.backend, elo::BackendKind::cpu);
  EXPECT_EQ(config.model.mode, elo::RegistrationMode::frame_to_frame);

  elo::Config full_name;
  elo_ros::applyConfigParameters(tree("mode: frame_to_frame"), full_name);
  EXPECT_EQ(full_name.model.mode, elo::RegistrationMode::frame_to_frame);
}

TEST(RosParameters, ReportsUnknownKeysUnderConfigSections) {
  elo::Config config;
  const auto unknown = elo_ros::applyConfigParameters(
      tree("ground: {max_slop_deg: 3, sensor_height: 1.8}\nbev: 5\npath_length: 10"), config);
  EXPECT_EQ(unknown, (std::vector<std::string>{"~bev", "~ground/max_slop_deg"}));
  EXPECT_DOUBLE_EQ(config.ground.sensor_height, 1.8) << "known keys beside an unknown one still apply";
}

TEST(RosParameters, WrongTypesNameTheRosParameter) {
  const auto message = [](const std::string& yaml) {
    elo::Config config;
    try {
      elo_ros::applyConfigParameters(tree(yaml), config);
    } catch (const elo::ConfigError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("ground: {max_slope_deg: steep}").find("~ground/max_slope_deg"), std::string::npos);
  EXPECT_NE(message("sensor: {image_width: 2048.5}").find("~sensor/image_width"), std::string::npos);
  EXPECT_NE(message("sensor: {beam_elevations_deg: [1, a]}").find("list of numbers"), std::string::npos);
  EXPECT_NE(message("normals: {method: magic}").find("range_adaptive"), std::string::npos);
  EXPECT_NE(message("mode: sideways").find("~mode"), std::string::npos);
}

TEST(RosParameters, EffectiveParametersReadBackToTheSameConfig) {
  elo::Config changed;
  changed.ground.max_slope_deg = 6.0;
  changed.sensor.beam_elevations_deg = {1.0, -1.0};
  changed.sensor.beam_count = 2;
  changed.model.motion_prior = elo::MotionPrior::none;
  XmlRpcValue parameters;
  for (const auto& [name, value] : elo_ros::effectiveParameters(changed)) {
    const size_t slash = name.find('/');
    parameters[name.substr(0, slash)][name.substr(slash + 1)] = value;
  }
  elo::Config read_back;
  EXPECT_TRUE(elo_ros::applyConfigParameters(parameters, read_back).empty());
  EXPECT_EQ(describe(read_back), describe(changed));
}

TEST(RosParameters, TrajectoryFormats) {
  EXPECT_EQ(elo_ros::parseTrajectoryFormat("kitti"), elo_ros::TrajectoryFormat::kitti);
  EXPECT_EQ(elo_ros::parseTrajectoryFormat("tum"), elo_ros::TrajectoryFormat::tum);
  EXPECT_THROW(elo_ros::parseTrajectoryFormat("csv"), std::invalid_argument);
}

}  // namespace
