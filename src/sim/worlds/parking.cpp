// A large parking lot: the vehicle drives down an aisle between rows of cars parked across it, with
// more rows beyond, light masts between back-to-back rows, a few trees, and store buildings at the far
// edge.
#include <cmath>

#include "worlds/recipe.hpp"

namespace elo::sim {
namespace {

constexpr double kStallWidth = 2.6;
constexpr double kStallDepth = 5.0;
constexpr double kAisleHalfWidth = 4.0;  // the vehicle drives down the middle of a 8 m aisle
constexpr double kRowPitch = 2.0 * kStallDepth + 2.0 * kAisleHalfWidth;  // two rows back to back and an aisle
constexpr int kRowPairs = 3;
constexpr double kStoreDistance = kAisleHalfWidth + kRowPairs * kRowPitch + 6.0;

// Cars parked across the aisle in each of the rows on this side, one stall per lot.
void furnishStall(Roadside& roadside, const Roadside::Lot& lot, Rng& rng) {
  for (int pair = 0; pair < kRowPairs; ++pair) {
    const double row_start = kAisleHalfWidth + pair * kRowPitch;
    for (const double stall_center : {row_start + 0.5 * kStallDepth, row_start + 1.5 * kStallDepth}) {
      if (!rng.chance(0.7)) continue;
      const double yaw = (rng.chance(0.5) ? 0.5 : -0.5) * M_PI + rng.uniform(-0.06, 0.06);
      roadside.addCar(lot, 0.5 * kStallWidth + rng.uniform(-0.2, 0.2), stall_center + rng.uniform(-0.3, 0.3), yaw,
                      rng, kAisleHalfWidth - 1.0);
    }
  }
}

void furnishBlock(Roadside& roadside, const Roadside::Lot& lot, Rng& rng) {
  for (int pair = 0; pair < kRowPairs; ++pair) {
    const double divider = kAisleHalfWidth + pair * kRowPitch + kStallDepth;
    if (rng.chance(0.6)) roadside.addPole(lot, rng.uniform(0.0, lot.length), divider, 0.15, 10.0, 1.0, kAisleHalfWidth);
    if (rng.chance(0.2)) roadside.addTree(lot, rng.uniform(0.0, lot.length), divider, rng, kAisleHalfWidth);
  }
  if (rng.chance(0.7)) {
    roadside.addBlock(lot, {0.0, lot.length - rng.uniform(0.0, 6.0), kStoreDistance + rng.uniform(0.0, 8.0), 30.0},
                      rng.uniform(6.0, 11.0), static_cast<float>(rng.uniform(0.3, 0.6)), kStoreDistance - 2.0, 0.0,
                      randomWindows(rng));
  }
}

}  // namespace

WorldRecipe parkingRecipe() {
  WorldRecipe recipe;
  recipe.cruise_speed = 5.0;
  // A nearly flat lot that drains through gentle swells.
  recipe.terrain = {{2, 60.0, 120.0, 0.004}, {1, 400.0, 800.0, 0.01}};
  recipe.cross_section = [](double) { return 0.0; };
  recipe.cross_section_reach = 0.0;
  recipe.clearance_reach = kStoreDistance - 2.0;
  recipe.ground_reflectivity = 0.15f;
  recipe.furnish = [](Roadside& roadside) {
    roadside.forEachLot(kAisleHalfWidth + kStallDepth, [](Rng&) { return kStallWidth; },
                        [&roadside](const Roadside::Lot& lot, Rng& rng) { furnishStall(roadside, lot, rng); });
    roadside.forEachLot(kStoreDistance, [](Rng& rng) { return rng.uniform(30.0, 60.0); },
                        [&roadside](const Roadside::Lot& lot, Rng& rng) { furnishBlock(roadside, lot, rng); });
  };
  return recipe;
}

}  // namespace elo::sim
