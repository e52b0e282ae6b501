// A motorway: a wide flat carriageway, guard rails, verges with shrubs, embankments with belts of
// trees, now and then a sign or a stretch of noise barrier. Long runs offer little but the road and two rails: the
// feature-poor case for odometry.
#include <cmath>

#include "worlds/recipe.hpp"

namespace elo::sim {
namespace {

constexpr double kPavedHalfWidth = 9.0;  // three 3.5 m lanes and a shoulder, the vehicle in the middle lane
constexpr double kCrownSlope = 0.015;
constexpr double kRailDistance = 9.5;
constexpr double kVergeSlope = 0.06;      // grass falling away from the rail to the ditch
constexpr double kDitchBegin = 13.0;
constexpr double kDitchEnd = 17.0;
constexpr double kDitchDepth = 0.6;
constexpr double kEmbankmentEnd = 35.0;
constexpr double kEmbankmentHeight = 2.5;  // the cutting the motorway runs in

double crossSection(double distance) {
  const double paved_edge = -kCrownSlope * kPavedHalfWidth;
  if (distance < kPavedHalfWidth) return -kCrownSlope * distance;
  const double verge_bottom = paved_edge - kVergeSlope * (kDitchBegin - kPavedHalfWidth);
  if (distance < kDitchBegin) return paved_edge - kVergeSlope * (distance - kPavedHalfWidth);
  if (distance < kDitchEnd) {
    return verge_bottom - kDitchDepth * 0.5 * (1.0 - std::cos(2.0 * M_PI * (distance - kDitchBegin) / (kDitchEnd - kDitchBegin)));
  }
  return verge_bottom + (kEmbankmentHeight - verge_bottom) * smoothStep(kDitchEnd, kEmbankmentEnd, distance);
}

// A guard rail: a steel beam on posts every two metres, in lots of four metres so that it follows curves.
void addGuardRail(Roadside& roadside, const Roadside::Lot& lot) {
  roadside.addBlock(lot, {0.0, lot.length, kRailDistance, 0.1}, 0.32, 0.7f, kPavedHalfWidth, 0.42);
  for (double post = 0.0; post < lot.length; post += 2.0) {
    roadside.addBlock(lot, {post, 0.12, kRailDistance + 0.1, 0.12}, 0.75, 0.5f, kPavedHalfWidth);
  }
}

void furnishVerge(Roadside& roadside, const Roadside::Lot& lot, Rng& rng) {
  if (rng.chance(0.06)) {
    // A direction sign: a board on two posts, facing the traffic.
    const double along = rng.uniform(0.0, lot.length);
    roadside.addPole(lot, along, kRailDistance + 1.0, 0.1, 4.8, 0.0, kRailDistance);
    roadside.addPole(lot, along, kRailDistance + 4.5, 0.1, 4.8, 0.0, kRailDistance);
    roadside.addBlock(lot, {along - 0.15, 0.1, kRailDistance + 0.8, 3.9}, 2.2, 0.9f, kRailDistance, 2.6);
  }
  if (rng.chance(0.15)) {
    roadside.addBlock(lot, {0.0, lot.length, kRailDistance + 4.5, 0.3}, 3.5, 0.4f, kRailDistance + 2.0);
  }
  if (rng.chance(0.6)) {
    // Shrubs planted along the verge, between the rail and the ditch.
    for (double along = 0.0; along < lot.length; along += rng.uniform(1.5, 3.5)) {
      roadside.addBush(lot, along, rng.uniform(kRailDistance + 2.0, kDitchBegin), rng, kRailDistance + 1.5);
    }
  }
  if (rng.chance(0.5)) {
    // A belt of trees on the embankment.
    for (double along = 0.0; along < lot.length; along += rng.uniform(4.0, 9.0)) {
      roadside.addTree(lot, along, rng.uniform(kDitchEnd + 1.0, kEmbankmentEnd), rng, kDitchEnd);
    }
  }
}

}  // namespace

WorldRecipe highwayRecipe() {
  WorldRecipe recipe;
  recipe.cruise_speed = 25.0;
  recipe.terrain = {{2, 1500.0, 3000.0, 0.015}};
  recipe.cross_section = crossSection;
  recipe.cross_section_reach = kEmbankmentEnd;
  recipe.clearance_reach = kDitchEnd;
  recipe.ground_reflectivity = 0.12f;
  recipe.furnish = [](Roadside& roadside) {
    roadside.forEachLot(kRailDistance, [](Rng&) { return 4.0; },
                        [&roadside](const Roadside::Lot& lot, Rng&) { addGuardRail(roadside, lot); });
    roadside.forEachLot(kDitchEnd, [](Rng& rng) { return rng.uniform(40.0, 60.0); },
                        [&roadside](const Roadside::Lot& lot, Rng& rng) { furnishVerge(roadside, lot, rng); });
  };
  return recipe;
}

}  // namespace elo::sim
