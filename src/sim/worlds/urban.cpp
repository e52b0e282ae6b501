// A street canyon: a crowned road between kerbs and sidewalks, continuous facades with setbacks and
// gaps, cars parked along the kerbs, street lamps, signs and trees.
#include <cmath>

#include "worlds/recipe.hpp"

namespace elo::sim {
namespace {

constexpr double kRoadHalfWidth = 6.0;   // a lane and a parking lane each side
constexpr double kKerbWidth = 0.2;
constexpr double kKerbHeight = 0.15;
constexpr double kCrownSlope = 0.02;
constexpr double kSidewalkEnd = 9.0;     // where the building line starts
constexpr double kSidewalkSlope = 0.01;  // rising toward the buildings, to drain onto the road
constexpr double kParkedCarCenter = 5.0;

double crossSection(double distance) {
  const double road_edge = -kCrownSlope * kRoadHalfWidth;
  if (distance < kRoadHalfWidth) return -kCrownSlope * distance;
  const double kerb_top = road_edge + kKerbHeight;
  const double sidewalk_begin = kRoadHalfWidth + kKerbWidth;
  if (distance < sidewalk_begin) return road_edge + kKerbHeight * smoothStep(kRoadHalfWidth, sidewalk_begin, distance);
  return kerb_top + kSidewalkSlope * (std::min(distance, kSidewalkEnd) - sidewalk_begin);
}

// A building filling most of the lot, set back from the sidewalk, with a few protrusions (pilasters,
// balconies, shop canopies) so that facades are not bare planes.
void addBuilding(Roadside& roadside, const Roadside::Lot& lot, Rng& rng) {
  const double setback = rng.chance(0.3) ? rng.uniform(1.0, 3.0) : 0.0;
  const double gap = rng.uniform(0.0, 1.5);
  const Roadside::Footprint footprint{0.0, lot.length - gap, kSidewalkEnd + setback, rng.uniform(10.0, 22.0)};
  const double height = rng.uniform(6.0, 25.0);
  const float reflectivity = static_cast<float>(rng.uniform(0.2, 0.6));
  if (!roadside.addBlock(lot, footprint, height, reflectivity, kSidewalkEnd - 0.5, 0.0, randomWindows(rng))) return;
  const int protrusions = rng.uniformInt(0, 3);
  for (int i = 0; i < protrusions; ++i) {
    const double depth = rng.uniform(0.3, 1.2);
    const double length = rng.uniform(0.6, std::min(4.0, footprint.length));
    const double along = rng.uniform(0.0, footprint.length - length);
    const Roadside::Footprint bay{along, length, footprint.distance - depth, depth};
    const bool canopy = rng.chance(0.4);
    roadside.addBlock(lot, bay, canopy ? 0.3 : rng.uniform(2.5, height), reflectivity,
                      kRoadHalfWidth + kKerbWidth, canopy ? rng.uniform(2.5, 3.5) : 0.0);
  }
}

void furnishLot(Roadside& roadside, const Roadside::Lot& lot, Rng& rng) {
  if (rng.chance(0.85)) {
    addBuilding(roadside, lot, rng);
  } else if (rng.chance(0.5)) {
    // A gap in the row: a courtyard or side street, with the next building far back.
    const Roadside::Footprint back{0.0, lot.length, rng.uniform(22.0, 35.0), rng.uniform(10.0, 20.0)};
    roadside.addBlock(lot, back, rng.uniform(8.0, 20.0), static_cast<float>(rng.uniform(0.2, 0.6)), 20.0, 0.0,
                      randomWindows(rng));
  }
  for (double slot = 0.5; slot + 5.5 <= lot.length; slot += 6.0) {
    if (rng.chance(0.6)) roadside.addCar(lot, slot + 2.75, kParkedCarCenter, rng.uniform(-0.03, 0.03), rng, 3.6);
  }
  if (rng.chance(0.35)) {
    roadside.addPole(lot, rng.uniform(0.0, lot.length), kRoadHalfWidth + 0.6, 0.1, rng.uniform(6.0, 8.0), 1.5,
                     kRoadHalfWidth + 0.4);
  }
  if (rng.chance(0.2)) {
    // A traffic sign: a post with a retroreflective board facing the traffic.
    const double along = rng.uniform(0.0, lot.length);
    roadside.addPole(lot, along, kRoadHalfWidth + 0.5, 0.04, 2.6, 0.0, kRoadHalfWidth + 0.3);
    roadside.addBlock(lot, {along - 0.025, 0.05, kRoadHalfWidth + 0.2, 0.6}, 0.6, 0.9f, kRoadHalfWidth, 2.0);
  }
  if (rng.chance(0.5)) roadside.addTree(lot, rng.uniform(0.0, lot.length), kRoadHalfWidth + 1.4, rng, kRoadHalfWidth + 1.0);
}

}  // namespace

WorldRecipe urbanRecipe() {
  WorldRecipe recipe;
  recipe.cruise_speed = 10.0;
  recipe.terrain = {{2, 400.0, 900.0, 0.012}, {2, 60.0, 150.0, 0.004}};
  recipe.cross_section = crossSection;
  recipe.cross_section_reach = kSidewalkEnd;
  recipe.clearance_reach = 20.0;
  recipe.ground_reflectivity = 0.15f;
  recipe.furnish = [](Roadside& roadside) {
    roadside.forEachLot(kSidewalkEnd + 2.0, [](Rng& rng) { return rng.uniform(8.0, 24.0); },
                        [&roadside](const Roadside::Lot& lot, Rng& rng) { furnishLot(roadside, lot, rng); });
  };
  return recipe;
}

}  // namespace elo::sim
