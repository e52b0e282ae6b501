// What makes a world family: its terrain, the road's cross-section, its traffic speed and the
// roadside it furnishes. One file per family defines its recipe.
#pragma once

#include <algorithm>
#include <functional>
#include <vector>

#include "worlds/roadside.hpp"

namespace elo::sim {

// `count` sinusoidal undulations with wavelengths in [min_wavelength, max_wavelength], each with an
// amplitude that gives it the steepest slope `slope` (so the terrain's slope stays bounded).
struct WaveBand {
  int count = 0;
  double min_wavelength = 100.0;
  double max_wavelength = 100.0;
  double slope = 0.01;
};

struct WorldRecipe {
  double cruise_speed = 10.0;  // m/s
  std::vector<WaveBand> terrain;
  // Height of the ground above the terrain at a distance from the route: crown, kerbs, ditches. It
  // must be constant from `cross_section_reach` on.
  std::function<double(double distance)> cross_section;
  double cross_section_reach = 20.0;
  // The largest clearance from the route that the roadside checks (the road's distance queries must
  // reach that far).
  double clearance_reach = 20.0;
  float ground_reflectivity = 0.15f;
  std::function<void(Roadside&)> furnish;
};

WorldRecipe urbanRecipe();
WorldRecipe highwayRecipe();
WorldRecipe countryRecipe();
WorldRecipe parkingRecipe();
WorldRecipe tunnelRecipe();
WorldRecipe indoorRecipe();

// Smooth step from 0 at `begin` to 1 at `end` (zero slope at both ends).
inline double smoothStep(double begin, double end, double x) {
  const double t = std::clamp((x - begin) / (end - begin), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace elo::sim
