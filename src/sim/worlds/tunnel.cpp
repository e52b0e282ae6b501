// A long road tunnel: the route starts on an open approach in a cutting (fence posts, lamp posts,
// trees), enters a portal after kPortalDistance metres and then runs kTunnelLength metres between smooth
// walls under a flat ceiling, lit by continuous lamp strips. Nothing inside varies along the axis (no
// niches, signs or fans), so a LiDAR there cannot observe its translation along the tunnel: the degenerate
// case of odometry. On a curving route the tunnel curves with it.
#include <cmath>

#include "worlds/recipe.hpp"

namespace elo::sim {
namespace {

constexpr double kPortalDistance = 100.0;  // m along the route from its start to the tunnel mouth
constexpr double kTunnelLength = 2000.0;
// m of wall and ceiling per box, so that they follow curves. Not shorter: Roadside skips a lot when most
// of its frontage points (2 m apart) lie within 3 m of the last lot's, which for 4 m lots is every other.
constexpr double kShellLot = 6.0;
constexpr double kJointOverlap = 0.3;      // m each box reaches into the next: no gaps on the outside of a curve

constexpr double kRoadHalfWidth = 4.0;     // two 3.5 m lanes and shoulders, the vehicle on the centre line
constexpr double kCrownSlope = 0.015;
constexpr double kKerbWidth = 0.15;
constexpr double kKerbHeight = 0.15;
constexpr double kWallDistance = 5.5;      // the walkway beside the road ends at the wall
constexpr double kWallThickness = 1.0;
constexpr double kCeilingHeight = 5.2;     // clearance above the road
constexpr double kSlabThickness = 0.6;
constexpr double kLampStripDistance = 2.5;  // from the centre line, on the ceiling
constexpr double kVergeEnd = 9.0;          // outside: a flat verge, then the cutting's slope
constexpr double kCuttingEnd = 30.0;
constexpr double kCuttingHeight = 10.0;

double crossSection(double distance) {
  const double road_edge = -kCrownSlope * kRoadHalfWidth;
  if (distance < kRoadHalfWidth) return -kCrownSlope * distance;
  if (distance < kVergeEnd) {
    return road_edge + kKerbHeight * smoothStep(kRoadHalfWidth, kRoadHalfWidth + kKerbWidth, distance);
  }
  const double walkway = road_edge + kKerbHeight;
  return walkway + (kCuttingHeight - walkway) * smoothStep(kVergeEnd, kCuttingEnd, distance);
}

// Whether `along` metres into the lot lies inside the tunnel, by distance along the route.
bool insideTunnel(const Roadside& roadside, const Roadside::Lot& lot, double along) {
  const double from_start = lot.begin + along - roadside.routeStart();
  return from_start >= kPortalDistance && from_start < kPortalDistance + kTunnelLength;
}

// One side's wall, half of the ceiling (reaching past the centre line) and a lamp strip under it.
void addShell(Roadside& roadside, const Roadside::Lot& lot) {
  const double length = lot.length + kJointOverlap;
  roadside.addBlock(lot, {0.0, length, kWallDistance, kWallThickness}, kCeilingHeight + kSlabThickness, 0.5f,
                    kWallDistance - 0.5);
  roadside.addBlock(lot, {0.0, length, -0.5, kWallDistance + kWallThickness + 0.5}, kSlabThickness, 0.3f, 0.0,
                    kCeilingHeight);
  roadside.addBlock(lot, {0.0, length, kLampStripDistance, 0.3}, 0.08, 0.9f, 0.0, kCeilingHeight - 0.08);
}

// The face around a tunnel mouth: a wall across the cutting beside the opening and above it.
void addHeadwall(Roadside& roadside, const Roadside::Lot& lot) {
  roadside.addBlock(lot, {0.0, 1.0, kWallDistance, kCuttingEnd}, kCeilingHeight + 8.0, 0.5f, kWallDistance - 0.5);
  roadside.addBlock(lot, {0.0, 1.0, -0.5, kWallDistance + 0.5}, 8.0, 0.5f, 0.0, kCeilingHeight);
}

void furnishShell(Roadside& roadside, const Roadside::Lot& lot) {
  const double middle = 0.5 * lot.length;
  if (!insideTunnel(roadside, lot, middle)) return;
  addShell(roadside, lot);
  const bool entrance = !insideTunnel(roadside, lot, middle - lot.length);
  const bool exit = !insideTunnel(roadside, lot, middle + lot.length);
  if (entrance) addHeadwall(roadside, lot);
  if (exit) addHeadwall(roadside, {lot.begin + lot.length - 1.0, 1.0, lot.side, lot.index});
}

// The open road: fence posts along the verge, lamp posts, trees and shrubs on the cutting's slope.
void furnishOpen(Roadside& roadside, const Roadside::Lot& lot, Rng& rng) {
  const auto open = [&](double along) { return !insideTunnel(roadside, lot, along); };
  for (double post = 0.0; post < lot.length; post += 2.5) {
    if (open(post)) roadside.addPole(lot, post, kWallDistance, 0.06, 1.1, 0.0, kRoadHalfWidth);
  }
  const double lamp = rng.uniform(0.0, lot.length);
  if (rng.chance(0.7) && open(lamp)) roadside.addPole(lot, lamp, kWallDistance + 0.5, 0.12, 8.0, 1.8, kRoadHalfWidth);
  for (double along = rng.uniform(0.0, 5.0); along < lot.length; along += rng.uniform(4.0, 10.0)) {
    const double distance = rng.uniform(kVergeEnd, kCuttingEnd);
    if (!open(along)) continue;
    if (rng.chance(0.5)) {
      roadside.addTree(lot, along, distance, rng, kVergeEnd - 1.0);
    } else {
      roadside.addBush(lot, along, distance, rng, kVergeEnd - 1.0);
    }
  }
}

}  // namespace

WorldRecipe tunnelRecipe() {
  WorldRecipe recipe;
  recipe.cruise_speed = 16.0;  // 58 km/h: reached 85 m after the start, before the portal
  // No terrain undulation: walls and ceiling are upright boxes on each lot's ground, and a slope would
  // step the ceiling by centimetres every few metres, features along the axis a real tunnel does not have.
  recipe.cross_section = crossSection;
  recipe.cross_section_reach = kCuttingEnd;
  recipe.clearance_reach = kVergeEnd;
  recipe.ground_reflectivity = 0.15f;
  recipe.furnish = [](Roadside& roadside) {
    roadside.forEachLot(kWallDistance, [](Rng&) { return kShellLot; },
                        [&roadside](const Roadside::Lot& lot, Rng&) { furnishShell(roadside, lot); });
    roadside.forEachLot(kVergeEnd, [](Rng& rng) { return rng.uniform(20.0, 40.0); },
                        [&roadside](const Roadside::Lot& lot, Rng& rng) { furnishOpen(roadside, lot, rng); });
  };
  return recipe;
}

}  // namespace elo::sim
