// The sensors the simulator knows by name, each described by a YAML file in the project's config/.
#pragma once

#include <string>
#include <vector>

#include "elo/config.hpp"

namespace elo::sim {

std::vector<std::string> sensorNames();  // hdl64, vlp16, vlp32, os1-64, os1-128

// Overrides `config` with config/NAME.yaml. Throws std::invalid_argument for an unknown name, and
// ConfigError or IoError for a file that cannot be read.
void loadSensor(const std::string& name, Config& config);

}  // namespace elo::sim
