// The map rendering of localization (Backend::renderMap()) for a backend that has none: each call says so.
#include <stdexcept>
#include <string>

#include "elo/backend.hpp"

namespace elo {
namespace {

[[noreturn]] void refuseMaps(const Backend& backend) {
  throw std::runtime_error(std::string("the ") + backend.name() +
                           " backend cannot localize on a map: map rendering is implemented on the CPU backend "
                           "only (run localization with runtime.backend cpu)");
}

}  // namespace

void Backend::setMap(std::shared_ptr<const MapCloud> /*map*/) { refuseMaps(*this); }
void Backend::renderMap(const std::vector<int32_t>& /*points*/, const Eigen::Isometry3d& /*map_from_sensor*/) {
  refuseMaps(*this);
}
NormalEquations Backend::linearizeMap(const Eigen::Isometry3d& /*rendered_from_scan*/, double /*kernel_scale*/) {
  refuseMaps(*this);
}
const Model& Backend::mapModel() { refuseMaps(*this); }

}  // namespace elo
