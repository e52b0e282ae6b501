// Procedural, seeded worlds built along a route: the ground (terrain, hills, the road's cross-section)
// and the roadside objects exist wherever the route goes, to the sensor's reach on either side, and
// the same seed and route build the same world on every machine.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "elo/sim/centerline.hpp"
#include "elo/sim/ground.hpp"
#include "elo/sim/scene.hpp"
#include "elo/sim/trajectory.hpp"

namespace elo::sim {

enum class WorldFamily { urban, highway, country, parking, tunnel, indoor };
struct WorldRecipe;

std::optional<WorldFamily> worldFamilyFromName(const std::string& name);
std::string worldName(WorldFamily family);
std::vector<std::string> worldNames();
// The speed traffic drives at in this kind of world (m/s): procedural routes cruise at it.
double cruiseSpeed(WorldFamily family);

struct WorldOptions {
  uint64_t seed = 1;
  double reach = 130.0;  // m around the route that the ground covers: the sensor's range and a margin
  int moving_cars = 0;
};

// Cars driving along the road (both directions, in the lanes beside the vehicle's).
class Traffic {
 public:
  Traffic(const Centerline& road, const GroundSurface& ground, int count, double speed, uint64_t seed);

  // The cars within `radius` of `position` at `time`.
  std::vector<Primitive> carsNear(double time, const Eigen::Vector2d& position, double radius) const;

 private:
  struct Car {
    double start = 0.0;  // arc length at time 0
    double speed = 0.0;  // along the route; negative: oncoming
    double lateral = 0.0;  // offset to the left of the route
    uint64_t body_seed = 0;
  };
  const Centerline& road_;
  const GroundSurface& ground_;
  std::vector<Car> cars_;
};

class World {
 public:
  World(WorldFamily family, const Route& route, const WorldOptions& options);
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  WorldFamily family() const { return family_; }
  const GroundSurface& ground() const { return *ground_; }
  const Centerline& road() const { return road_; }
  const Scene& scene() const { return scene_; }

  // What a sensor at `position` sees at `time`: the static scene and the moving cars within `radius`.
  std::unique_ptr<RayCaster> snapshot(double time, const Eigen::Vector3d& position, double radius) const;

 private:
  World(WorldFamily family, const WorldRecipe& recipe, const Route& route, const WorldOptions& options);

  WorldFamily family_;
  Centerline road_;
  std::shared_ptr<const HeightField> ground_;
  Scene scene_;
  Traffic traffic_;
};

}  // namespace elo::sim
