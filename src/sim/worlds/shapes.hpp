// Composite objects made of primitives, shared by the parked and the moving cars and by the roadside.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "elo/sim/primitives.hpp"
#include "elo/sim/rng.hpp"

namespace elo::sim {

struct CarBody {
  double length = 4.5;
  double width = 1.8;
  double cabin_height = 0.55;
  float reflectivity = 0.5f;  // paint: from dark (0.1) to white (0.9)

  static CarBody random(Rng& rng);
};

// A body box over the wheels and a cabin box on top, standing on the ground at `ground_z`.
void addCar(std::vector<Primitive>& out, const Eigen::Vector2d& position, double heading, double ground_z,
            const CarBody& body);

// The windows of a building of offices or flats.
WindowGrid randomWindows(Rng& rng);

// A trunk under an irregular canopy of overlapping ellipsoids.
void addTree(std::vector<Primitive>& out, const Eigen::Vector2d& position, double ground_z, Rng& rng);

// A low blob of a few ellipsoids on the ground.
void addBush(std::vector<Primitive>& out, const Eigen::Vector2d& position, double ground_z, Rng& rng);

}  // namespace elo::sim
