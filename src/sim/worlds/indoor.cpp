// A built-up indoor-like scene: a hall of corridors the route runs down, between walls 4 m either side
// under a 4.5 m ceiling, with doorways into rooms behind them, pillars and stacked crates along the
// walls. Close surfaces all round and a flat floor: what a robot or a small vehicle sees indoors, and a
// place where a turn sweeps the whole view within a scan.
#include <cmath>

#include "worlds/recipe.hpp"

namespace elo::sim {
namespace {

constexpr double kWallDistance = 4.0;     // from the route to each corridor wall
constexpr double kWallThickness = 0.3;
constexpr double kCeilingHeight = 4.5;    // above the floor
constexpr double kSlabThickness = 0.4;
constexpr double kDoorWidth = 1.4;
constexpr double kRoomDepth = 6.0;        // behind a doorway, to the room's back wall
constexpr double kClearance = 2.0;        // m kept free around the route: pillars and crates stand beyond it
constexpr double kJointOverlap = 0.2;     // m each wall and slab reaches into the next lot

// One side's stretch of corridor: the wall (a doorway in some, a room behind it), half the ceiling
// (reaching past the centre line), and what stands along the wall.
void furnishCorridor(Roadside& roadside, const Roadside::Lot& lot, Rng& rng) {
  const double length = lot.length + kJointOverlap;
  const float wall_reflectivity = static_cast<float>(rng.uniform(0.3, 0.7));
  if (rng.chance(0.3) && lot.length > kDoorWidth + 1.0) {
    const double door = rng.uniform(0.5, lot.length - kDoorWidth - 0.5);
    roadside.addBlock(lot, {0.0, door, kWallDistance, kWallThickness}, kCeilingHeight, wall_reflectivity, kClearance);
    roadside.addBlock(lot, {door + kDoorWidth, length - door - kDoorWidth, kWallDistance, kWallThickness},
                      kCeilingHeight, wall_reflectivity, kClearance);
    roadside.addBlock(lot, {door, kDoorWidth, kWallDistance, kWallThickness}, kCeilingHeight - 2.1, wall_reflectivity,
                      kClearance, 2.1);  // the lintel
    roadside.addBlock(lot, {0.0, length, kWallDistance + kRoomDepth, kWallThickness}, kCeilingHeight, 0.5f, kClearance);
  } else {
    roadside.addBlock(lot, {0.0, length, kWallDistance, kWallThickness}, kCeilingHeight, wall_reflectivity, kClearance);
  }
  roadside.addBlock(lot, {0.0, length, -0.5, kWallDistance + kWallThickness + 0.5}, kSlabThickness, 0.3f, 0.0,
                    kCeilingHeight);
  if (rng.chance(0.4)) {
    roadside.addBlock(lot, {rng.uniform(0.0, lot.length - 0.4), 0.4, kWallDistance - 0.4, 0.4}, kCeilingHeight, 0.4f,
                      kClearance);  // a pillar against the wall
  }
  for (double along = rng.uniform(0.0, 2.0); along + 1.2 < lot.length; along += rng.uniform(2.0, 5.0)) {
    if (!rng.chance(0.5)) continue;
    const double depth = rng.uniform(0.8, 1.5);
    roadside.addBlock(lot, {along, rng.uniform(0.8, 1.2), kWallDistance - depth, depth}, rng.uniform(0.5, 2.2),
                      static_cast<float>(rng.uniform(0.2, 0.6)), kClearance);  // crates
  }
}

}  // namespace

WorldRecipe indoorRecipe() {
  WorldRecipe recipe;
  recipe.cruise_speed = 6.0;  // a small vehicle in a hall, driven hard
  recipe.cross_section = [](double) { return 0.0; };  // a flat floor
  recipe.cross_section_reach = 0.0;
  recipe.clearance_reach = kWallDistance + kRoomDepth + 1.0;
  recipe.ground_reflectivity = 0.25f;
  recipe.furnish = [](Roadside& roadside) {
    roadside.forEachLot(kWallDistance, [](Rng& rng) { return rng.uniform(4.0, 8.0); },
                        [&roadside](const Roadside::Lot& lot, Rng& rng) { furnishCorridor(roadside, lot, rng); });
  };
  return recipe;
}

}  // namespace elo::sim
