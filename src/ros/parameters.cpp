#include "parameters.hpp"

#include <ros/console.h>

#include <algorithm>
#include <set>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <variant>

namespace elo_ros {
namespace {

using XmlRpc::XmlRpcValue;

std::string rosName(const std::string& dotted_key) {
  std::string name = "~" + dotted_key;
  std::replace(name.begin(), name.end(), '.', '/');
  return name;
}

std::pair<std::string, std::string> splitKey(const std::string& dotted_key) {
  const size_t dot = dotted_key.find('.');
  return {dotted_key.substr(0, dot), dotted_key.substr(dot + 1)};
}

elo::ParameterValue toParameterValue(XmlRpcValue& value, const std::string& name) {
  switch (value.getType()) {
    case XmlRpcValue::TypeBoolean: return static_cast<bool>(value);
    case XmlRpcValue::TypeInt: return static_cast<int>(value);
    case XmlRpcValue::TypeDouble: return static_cast<double>(value);
    case XmlRpcValue::TypeString: return static_cast<std::string>(value);
    case XmlRpcValue::TypeArray: {
      std::vector<double> numbers;
      for (int i = 0; i < value.size(); ++i) {
        XmlRpcValue& item = value[i];
        if (item.getType() == XmlRpcValue::TypeInt) {
          numbers.push_back(static_cast<int>(item));
        } else if (item.getType() == XmlRpcValue::TypeDouble) {
          numbers.push_back(static_cast<double>(item));
        } else {
          throw elo::ConfigError("parameter " + name + " must be a list of numbers");
        }
      }
      return numbers;
    }
    default:
      throw elo::ConfigError("parameter " + name + " must be a boolean, a number, a string or a list of numbers");
  }
}

XmlRpcValue toXmlRpc(const elo::ParameterValue& value) {
  return std::visit(
      [](const auto& v) -> XmlRpcValue {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::vector<double>>) {
          XmlRpcValue list;
          list.setSize(static_cast<int>(v.size()));
          for (size_t i = 0; i < v.size(); ++i) list[static_cast<int>(i)] = v[i];
          return list;
        } else {
          return XmlRpcValue(T(v));
        }
      },
      value);
}

void setParameter(const elo::Parameter& parameter, XmlRpcValue& value, const std::string& name) {
  try {
    parameter.set(toParameterValue(value, name));
  } catch (const elo::ConfigError& error) {
    throw elo::ConfigError(name + ": " + error.what());
  }
}

const elo::Parameter& findParameter(const std::vector<elo::Parameter>& table, const std::string& key) {
  const auto parameter = std::find_if(table.begin(), table.end(), [&](const auto& p) { return p.key == key; });
  if (parameter == table.end()) throw std::logic_error("elo::parameters() has no '" + key + "'");
  return *parameter;
}

// The node-level names for the parameters a launch file sets most often.
void applyShortcuts(XmlRpcValue& tree, const std::vector<elo::Parameter>& table) {
  const std::pair<const char*, const char*> shortcuts[] = {
      {"backend", "runtime.backend"}, {"threads", "runtime.threads"}, {"mode", "model.mode"}};
  for (const auto& [shortcut, key] : shortcuts) {
    if (!tree.hasMember(shortcut)) continue;
    XmlRpcValue value = tree[shortcut];
    if (std::string(shortcut) == "mode" && value.getType() == XmlRpcValue::TypeString) {
      // elo_run's --mode spelling.
      const std::string mode = value;
      if (mode == "f2m") value = std::string("frame_to_model");
      if (mode == "f2f") value = std::string("frame_to_frame");
    }
    setParameter(findParameter(table, key), value, std::string("~") + shortcut);
  }
}

std::vector<std::string> unknownSectionMembers(XmlRpcValue& tree, const std::vector<elo::Parameter>& table) {
  std::set<std::string> known;
  std::set<std::string> sections;
  for (const elo::Parameter& parameter : table) {
    known.insert(parameter.key);
    sections.insert(splitKey(parameter.key).first);
  }
  std::vector<std::string> unknown;
  for (const std::string& section : sections) {
    if (!tree.hasMember(section)) continue;
    XmlRpcValue& members = tree[section];
    if (members.getType() != XmlRpcValue::TypeStruct) {
      unknown.push_back("~" + section);
      continue;
    }
    for (const auto& [member, value] : members) {
      if (known.count(section + "." + member) == 0) unknown.push_back("~" + section + "/" + member);
    }
  }
  return unknown;
}

const char* expectedType(bool) { return "true or false"; }
const char* expectedType(int) { return "an integer"; }
const char* expectedType(double) { return "a number"; }
const char* expectedType(const std::string&) { return "a string"; }

// Reads `~name` into `value` when it is set. A value of another type is an error: quietly keeping the
// default would run the node with a setting nobody chose.
template <typename T>
void readSetting(const ros::NodeHandle& private_node, const std::string& name, T& value) {
  if (!private_node.hasParam(name)) return;
  if (!private_node.getParam(name, value)) throw std::invalid_argument("~" + name + " must be " + expectedType(value));
}

}  // namespace

std::vector<std::string> applyConfigParameters(XmlRpcValue tree, elo::Config& config) {
  if (tree.getType() != XmlRpcValue::TypeStruct) return {};
  const std::vector<elo::Parameter> table = elo::parameters(config);
  for (const elo::Parameter& parameter : table) {
    const auto [section, member] = splitKey(parameter.key);
    if (!tree.hasMember(section) || tree[section].getType() != XmlRpcValue::TypeStruct ||
        !tree[section].hasMember(member)) {
      continue;
    }
    setParameter(parameter, tree[section][member], rosName(parameter.key));
  }
  applyShortcuts(tree, table);
  return unknownSectionMembers(tree, table);
}

std::vector<std::pair<std::string, XmlRpcValue>> effectiveParameters(elo::Config& config) {
  std::vector<std::pair<std::string, XmlRpcValue>> named_values;
  for (const elo::Parameter& parameter : elo::parameters(config)) {
    named_values.emplace_back(rosName(parameter.key).substr(1), toXmlRpc(parameter.get()));
  }
  return named_values;
}

elo::Config readConfig(ros::NodeHandle& private_node, const std::string& logger) {
  XmlRpcValue tree;
  private_node.getParam(private_node.getNamespace(), tree);
  elo::Config config;
  const std::vector<std::string> unknown = applyConfigParameters(tree, config);
  if (!unknown.empty()) {
    std::string names;
    for (const std::string& name : unknown) names += (names.empty() ? "" : ", ") + name;
    ROS_WARN_NAMED(logger, "unknown parameters ignored (no such odometry parameter, see config/*.yaml): %s",
                   names.c_str());
  }
  elo::validate(config);
  for (const auto& [name, value] : effectiveParameters(config)) private_node.setParam(name, value);
  return config;
}

NodeSettings readNodeSettings(const ros::NodeHandle& private_node) {
  NodeSettings settings;
  const auto read = [&](const std::string& name, auto& value) { readSetting(private_node, name, value); };
  read("odom_frame", settings.odom_frame);
  read("base_frame", settings.base_frame);
  read("publish_sensor_frame_directly", settings.publish_sensor_frame_directly);
  read("publish_tf", settings.publish_tf);
  read("process_every_scan", settings.process_every_scan);
  read("path_length", settings.path_length);
  read("model_publish_rate", settings.model_publish_rate);
  read("tf_timeout", settings.tf_timeout);
  read("build_map", settings.build_map);
  read("map_publish_period", settings.map_publish_period);
  read("map_publish_points", settings.map_publish_points);
  read("save_trajectory_on_shutdown", settings.save_trajectory_on_shutdown);
  read("imu_mount_from_tf", settings.imu_mount_from_tf);
  read("imu_max_wait", settings.imu_max_wait);
  settings.outputs = readOutputFiles(private_node);
  if (settings.odom_frame.empty()) throw std::invalid_argument("~odom_frame must not be empty");
  if (settings.base_frame.empty()) throw std::invalid_argument("~base_frame must not be empty");
  if (settings.path_length < 0) throw std::invalid_argument("~path_length must not be negative");
  if (settings.model_publish_rate < 0.0) throw std::invalid_argument("~model_publish_rate must not be negative");
  if (settings.map_publish_period < 0.0) throw std::invalid_argument("~map_publish_period must not be negative");
  if (settings.map_publish_points < 1) throw std::invalid_argument("~map_publish_points must be positive");
  if (settings.tf_timeout < 0.0) throw std::invalid_argument("~tf_timeout must not be negative");
  if (settings.imu_max_wait < 0.0) throw std::invalid_argument("~imu_max_wait must not be negative");
  parseTrajectoryFormat(settings.outputs.trajectory_format);
  return settings;
}

OutputFiles readOutputFiles(const ros::NodeHandle& private_node) {
  OutputFiles files;
  readSetting(private_node, "trajectory_file", files.trajectory_file);
  readSetting(private_node, "trajectory_format", files.trajectory_format);
  readSetting(private_node, "map_file", files.map_file);
  readSetting(private_node, "model_file", files.model_file);
  return files;
}

TrajectoryFormat parseTrajectoryFormat(const std::string& text) {
  if (text == "kitti") return TrajectoryFormat::kitti;
  if (text == "tum") return TrajectoryFormat::tum;
  throw std::invalid_argument("~trajectory_format must be kitti or tum, got '" + text + "'");
}

}  // namespace elo_ros
