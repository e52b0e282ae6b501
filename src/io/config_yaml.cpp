#include "elo/io/config_yaml.hpp"

#include <yaml-cpp/yaml.h>

#include <map>
#include <optional>
#include <type_traits>

#include "elo/io/io_error.hpp"
#include "text_format.hpp"

namespace elo {
namespace {

using ParameterTable = std::map<std::string, const Parameter*>;

std::string location(const std::string& path, const YAML::Node& node) {
  return path + ":" + std::to_string(node.Mark().line + 1);
}

std::string expectedType(const ParameterValue& value) {
  return std::visit(
      [](const auto& current) -> std::string {
        using T = std::decay_t<decltype(current)>;
        if constexpr (std::is_same_v<T, bool>) return "true or false";
        if constexpr (std::is_same_v<T, int>) return "an integer";
        if constexpr (std::is_same_v<T, double>) return "a number";
        if constexpr (std::is_same_v<T, std::string>) return "a string";
        if constexpr (std::is_same_v<T, std::vector<double>>) return "a sequence of numbers";
      },
      value);
}

// The YAML value as the alternative the parameter holds now, so that `5` sets a double parameter and
// `5.5` is refused for an integer one; nullopt when the value does not convert. yaml-cpp decodes a
// sequence element by element with as<>(), which throws for an element that is not a number (`[1, 2x]`)
// instead of reporting failure; that too is a value that does not convert.
std::optional<ParameterValue> convertToCurrentType(const YAML::Node& node, const ParameterValue& current) {
  return std::visit(
      [&node](const auto& current_value) -> std::optional<ParameterValue> {
        using T = std::decay_t<decltype(current_value)>;
        const bool shape_matches = std::is_same_v<T, std::vector<double>> ? node.IsSequence() : node.IsScalar();
        T converted;
        try {
          if (shape_matches && YAML::convert<T>::decode(node, converted)) {
            return converted;
          }
          return std::nullopt;
        } catch (const YAML::BadConversion&) {
          return std::nullopt;
        }
      },
      current);
}

void setParameter(const Parameter& parameter, const YAML::Node& node, const std::string& path) {
  const ParameterValue current = parameter.get();
  const std::optional<ParameterValue> value = convertToCurrentType(node, current);
  if (!value) {
    const std::string found = node.IsScalar() ? ", got '" + node.Scalar() + "'" : "";
    throw ConfigError(location(path, node) + ": '" + parameter.key + "' expects " + expectedType(current) + found);
  }
  try {
    parameter.set(*value);
  } catch (const ConfigError& error) {
    throw ConfigError(location(path, node) + ": " + error.what());
  }
}

void loadSection(const YAML::Node& section, const std::string& prefix, const ParameterTable& table,
                 const std::string& path) {
  for (const auto& entry : section) {
    if (!entry.first.IsScalar()) {  // `[a]: 1` or `? {a: 1}`: YAML allows it, a parameter path does not
      throw ConfigError(location(path, entry.first) + ": expected a parameter or section name, got a " +
                        (entry.first.IsNull() ? "null" : "sequence or map") + " as key");
    }
    const std::string key = prefix + entry.first.Scalar();
    const auto parameter = table.find(key);
    if (entry.second.IsMap() && parameter == table.end()) {
      loadSection(entry.second, key + ".", table, path);
    } else if (parameter == table.end()) {
      throw ConfigError(location(path, entry.first) + ": unknown parameter '" + key + "'");
    } else {
      setParameter(*parameter->second, entry.second, path);
    }
  }
}

YAML::Node parseYaml(std::istream& stream, const std::string& name) {
  try {
    return YAML::Load(stream);
  } catch (const YAML::ParserException& error) {
    throw IoError(name + ":" + std::to_string(error.mark.line + 1) + ": invalid YAML: " + error.msg);
  }
}

// The parameters as a tree of sections, in the order the table lists them.
struct YamlEntry {
  std::string name;
  const Parameter* parameter = nullptr;  // null for a section
  std::vector<YamlEntry> children;
};

YamlEntry& childNamed(YamlEntry& section, const std::string& name) {
  for (YamlEntry& child : section.children) {
    if (child.name == name) {
      return child;
    }
  }
  section.children.push_back(YamlEntry{name, nullptr, {}});
  return section.children.back();
}

YamlEntry buildTree(const std::vector<Parameter>& parameters) {
  YamlEntry root;
  for (const Parameter& parameter : parameters) {
    YamlEntry* section = &root;
    size_t begin = 0;
    for (size_t dot = parameter.key.find('.'); dot != std::string::npos; dot = parameter.key.find('.', begin)) {
      section = &childNamed(*section, parameter.key.substr(begin, dot - begin));
      begin = dot + 1;
    }
    childNamed(*section, parameter.key.substr(begin)).parameter = &parameter;
  }
  return root;
}

void emitValue(YAML::Emitter& out, const ParameterValue& value) {
  std::visit(
      [&out](const auto& current) {
        using T = std::decay_t<decltype(current)>;
        if constexpr (std::is_same_v<T, double>) {
          out << io_detail::formatDouble(current);
        } else if constexpr (std::is_same_v<T, std::vector<double>>) {
          out << YAML::Flow << YAML::BeginSeq;
          for (double element : current) {
            out << io_detail::formatDouble(element);
          }
          out << YAML::EndSeq;
        } else {
          out << current;
        }
      },
      value);
}

std::string comment(const Parameter& parameter) {
  std::string text = parameter.description;
  for (size_t i = 0; i < parameter.choices.size(); ++i) {
    text += (i == 0 ? " (one of: " : ", ") + parameter.choices[i];
  }
  return parameter.choices.empty() ? text : text + ")";
}

void emitSection(YAML::Emitter& out, const YamlEntry& section) {
  out << YAML::BeginMap;
  for (const YamlEntry& child : section.children) {
    out << YAML::Key << child.name << YAML::Value;
    if (child.parameter != nullptr) {
      emitValue(out, child.parameter->get());
      out << YAML::Comment(comment(*child.parameter));
    } else {
      emitSection(out, child);
    }
  }
  out << YAML::EndMap;
}

}  // namespace

void loadConfigYaml(const std::string& path, Config& config) {
  std::ifstream stream = io_detail::openForReading(path);
  loadConfigYaml(stream, path, config);
}

void loadConfigYaml(std::istream& stream, const std::string& name, Config& config) {
  const YAML::Node root = parseYaml(stream, name);
  if (!root.IsNull() && !root.IsMap()) {  // an empty file keeps every default
    throw ConfigError(name + ": the top level must be a map of parameter sections");
  }
  const std::vector<Parameter> table_entries = parameters(config);
  ParameterTable table;
  for (const Parameter& parameter : table_entries) {
    table.emplace(parameter.key, &parameter);
  }
  loadSection(root, "", table, name);
  try {
    validate(config);
  } catch (const ConfigError& error) {
    throw ConfigError(name + ": " + error.what());
  }
}

std::string dumpConfigYaml(const Config& config) {
  Config bound_copy = config;  // parameters() binds to a mutable Config; dumping must not change the caller's
  const std::vector<Parameter> table = parameters(bound_copy);
  YAML::Emitter out;
  emitSection(out, buildTree(table));
  return std::string(out.c_str()) + "\n";
}

}  // namespace elo
