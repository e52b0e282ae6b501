// A country road over rolling hills: a narrow crowned lane pair with gravel shoulders and ditches, a
// bumpy surface, hedges and trees along it, fences, utility poles, woods, copses and farm buildings in
// the fields.
#include <cmath>

#include "worlds/recipe.hpp"

namespace elo::sim {
namespace {

constexpr double kRoadHalfWidth = 3.5;
constexpr double kCrownSlope = 0.025;
constexpr double kShoulderEnd = 4.5;
constexpr double kShoulderSlope = 0.04;
constexpr double kDitchEnd = 6.5;
constexpr double kDitchDepth = 0.45;
constexpr double kFieldBegin = 8.0;  // where the ground is back at terrain level

double crossSection(double distance) {
  if (distance < kRoadHalfWidth) return -kCrownSlope * distance;
  const double road_edge = -kCrownSlope * kRoadHalfWidth;
  if (distance < kShoulderEnd) return road_edge - kShoulderSlope * (distance - kRoadHalfWidth);
  const double shoulder_edge = road_edge - kShoulderSlope * (kShoulderEnd - kRoadHalfWidth);
  if (distance < kDitchEnd) {
    const double phase = 2.0 * M_PI * (distance - kShoulderEnd) / (kDitchEnd - kShoulderEnd);
    return shoulder_edge - kDitchDepth * 0.5 * (1.0 - std::cos(phase));
  }
  return shoulder_edge * (1.0 - smoothStep(kDitchEnd, kFieldBegin, distance));
}

// A hedge: bushes packed along the lot, with gaps for field gates.
void addHedge(Roadside& roadside, const Roadside::Lot& lot, double distance, Rng& rng) {
  for (double along = rng.uniform(0.0, 1.0); along < lot.length; along += rng.uniform(1.0, 2.0)) {
    roadside.addBush(lot, along, distance + rng.uniform(-0.3, 0.3), rng, kDitchEnd);
  }
}

void furnishRoadside(Roadside& roadside, const Roadside::Lot& lot, Rng& rng) {
  if (rng.chance(0.85)) addHedge(roadside, lot, rng.uniform(7.5, 9.0), rng);
  if (rng.chance(0.8)) roadside.addTree(lot, rng.uniform(0.0, lot.length), rng.uniform(7.5, 12.0), rng, kDitchEnd);
  if (rng.chance(0.25)) {
    for (double post = 0.0; post < lot.length; post += 3.0) {
      roadside.addPole(lot, post, 10.0, 0.06, 1.2, 0.0, kDitchEnd);
    }
  }
}

void furnishField(Roadside& roadside, const Roadside::Lot& lot, Rng& rng) {
  if (rng.chance(0.3)) roadside.addPole(lot, rng.uniform(0.0, lot.length), 7.5, 0.14, 9.0, 0.0, kDitchEnd);
  if (rng.chance(0.45)) {
    // Woodland: trees every few metres from the roadside deep into the field.
    const double edge = rng.uniform(10.0, 20.0);
    for (double along = 0.0; along < lot.length; along += rng.uniform(3.0, 6.0)) {
      for (double distance = edge; distance < edge + 30.0; distance += rng.uniform(3.0, 6.0)) {
        roadside.addTree(lot, along, distance, rng, kFieldBegin);
      }
    }
  } else if (rng.chance(0.4)) {
    // A copse: trees clustered around a point in the field.
    const double along = rng.uniform(0.0, lot.length);
    const double distance = rng.uniform(18.0, 60.0);
    const int trees = rng.uniformInt(3, 10);
    for (int i = 0; i < trees; ++i) {
      roadside.addTree(lot, along + rng.uniform(-8.0, 8.0), distance + rng.uniform(-6.0, 6.0), rng, kFieldBegin);
    }
  }
  if (rng.chance(0.1)) {
    // A farm: a hall and a lower annexe.
    const double distance = rng.uniform(20.0, 50.0);
    const double along = rng.uniform(0.0, std::max(0.0, lot.length - 12.0));
    roadside.addBlock(lot, {along, 12.0, distance, 9.0}, rng.uniform(4.0, 7.0), 0.45f, kFieldBegin);
    roadside.addBlock(lot, {along + 12.0, 6.0, distance + 1.0, 7.0}, rng.uniform(2.5, 3.5), 0.35f, kFieldBegin);
  }
}

}  // namespace

WorldRecipe countryRecipe() {
  WorldRecipe recipe;
  recipe.cruise_speed = 18.0;
  // Rolling hills (up to a few percent each) and short bumps of about a centimetre in the surface.
  recipe.terrain = {{3, 300.0, 900.0, 0.025}, {4, 3.0, 12.0, 0.008}};
  recipe.cross_section = crossSection;
  recipe.cross_section_reach = kFieldBegin;
  recipe.clearance_reach = kFieldBegin;
  recipe.ground_reflectivity = 0.2f;
  recipe.furnish = [](Roadside& roadside) {
    roadside.forEachLot(10.0, [](Rng& rng) { return rng.uniform(6.0, 15.0); },
                        [&roadside](const Roadside::Lot& lot, Rng& rng) { furnishRoadside(roadside, lot, rng); });
    roadside.forEachLot(40.0, [](Rng& rng) { return rng.uniform(30.0, 50.0); },
                        [&roadside](const Roadside::Lot& lot, Rng& rng) { furnishField(roadside, lot, rng); });
  };
  return recipe;
}

}  // namespace elo::sim
