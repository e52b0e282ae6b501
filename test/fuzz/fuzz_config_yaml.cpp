// The YAML parameter loader on arbitrary text: it sets parameters or throws IoError (not YAML) or
// ConfigError (naming the parameter), never crashes. A configuration it accepts must survive the round
// trip config_yaml.hpp promises: dumped and loaded again, it dumps the same.
#include <sstream>

#include "elo/config.hpp"
#include "elo/io/config_yaml.hpp"
#include "elo/io/io_error.hpp"
#include "fuzz_support.hpp"

namespace {

void expectDumpRoundTrips(const elo::Config& config) {
  const std::string dumped = elo::dumpConfigYaml(config);
  std::istringstream stream(dumped);
  elo::Config reloaded;
  elo::loadConfigYaml(stream, "dumped configuration", reloaded);
  elo::fuzz::expectProperty(elo::dumpConfigYaml(reloaded) == dumped, "a dumped configuration loads back the same");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream stream(elo::fuzz::bytesAsString(data, size));
  elo::Config config;
  try {
    elo::loadConfigYaml(stream, elo::fuzz::kInputName, config);
  } catch (const elo::IoError&) {
    return 0;  // not YAML
  } catch (const elo::ConfigError&) {
    return 0;  // an unknown key, a wrong type or an impossible value
  }
  expectDumpRoundTrips(config);
  return 0;
}
