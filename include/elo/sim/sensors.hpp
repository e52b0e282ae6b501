// The sensors the simulator knows by name, each described by a YAML file in the project's config/.
#pragma once

#include <string>
#include <vector>

#include "elo/config.hpp"

namespace elo::sim {

// The supported sensors of the README's table: config/NAME.yaml for each.
std::vector<std::string> sensorNames();

// Overrides `config` with config/NAME.yaml. Throws std::invalid_argument for an unknown name, and
// ConfigError or IoError for a file that cannot be read.
void loadSensor(const std::string& name, Config& config);

}  // namespace elo::sim
