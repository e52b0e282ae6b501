#include "elo/sim/sensors.hpp"

#include <algorithm>
#include <stdexcept>

#include "elo/io/config_yaml.hpp"

namespace elo::sim {

std::vector<std::string> sensorNames() {
  return {"hdl64",    "vlp16",     "vlp32", "vls128", "hdl32",                          // Velodyne
          "os0-64",   "os0-128",   "os1-64", "os1-128", "os2-64", "os2-128",            // Ouster
          "pandar64", "pandar40p", "xt16", "xt32", "xt32m", "ot128", "qt64", "qt128",   // Hesai
          "helios16", "helios5515", "rubyplus", "bpearl"};                              // RoboSense
}

void loadSensor(const std::string& name, Config& config) {
  const std::vector<std::string> names = sensorNames();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    throw std::invalid_argument("unknown sensor '" + name + "'");
  }
  loadConfigYaml(std::string(ELO_SIM_CONFIG_DIR) + "/" + name + ".yaml", config);
}

}  // namespace elo::sim
