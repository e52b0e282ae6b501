#include "elo/sim/sensors.hpp"

#include <algorithm>
#include <stdexcept>

#include "elo/io/config_yaml.hpp"

namespace elo::sim {

std::vector<std::string> sensorNames() { return {"hdl64", "vlp16", "vlp32", "os1-64", "os1-128"}; }

void loadSensor(const std::string& name, Config& config) {
  const std::vector<std::string> names = sensorNames();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    throw std::invalid_argument("unknown sensor '" + name + "'");
  }
  loadConfigYaml(std::string(ELO_SIM_CONFIG_DIR) + "/" + name + ".yaml", config);
}

}  // namespace elo::sim
