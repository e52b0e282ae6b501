// YAML files of parameters: nested maps whose paths are the dotted keys of elo::parameters().
#pragma once

#include <istream>
#include <string>

#include "elo/config.hpp"

namespace elo {

// Overrides the parameters of `config` that the file sets, then validates the result. Throws
// ConfigError naming the file, the key and its line for an unknown key or a value of the wrong type,
// and IoError for a file that cannot be read or parsed.
void loadConfigYaml(const std::string& path, Config& config);
// The same for YAML text on a stream; `name` stands for the file in error messages.
void loadConfigYaml(std::istream& stream, const std::string& name, Config& config);

// Every parameter as nested YAML, each with its description (and choices) as a comment; loading the
// text back with loadConfigYaml gives the same configuration.
std::string dumpConfigYaml(const Config& config);

}  // namespace elo
