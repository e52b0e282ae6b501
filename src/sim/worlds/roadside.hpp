// Furnishes the sides of the road. A world family walks each side of the route in lots and places
// shapes by road coordinates: `along` the lot from its start, and `distance` out from the route.
// Every shape is checked against the whole route, so a route that turns back on itself (laps, U-turns,
// KITTI's loops) never finds a building standing on its road; and a stretch of road driven a second
// time is not furnished again, so it looks the same on every visit.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "elo/sim/centerline.hpp"
#include "elo/sim/ground.hpp"
#include "elo/sim/primitives.hpp"
#include "elo/sim/rng.hpp"
#include "worlds/shapes.hpp"

namespace elo::sim {

class Roadside {
 public:
  struct Lot {
    double begin = 0.0;   // arc length of its start along the route
    double length = 0.0;
    double side = 1.0;    // +1 left of the route, -1 right
    int index = 0;        // count of lots on this side before it
  };

  // A rectangle beside the road: `length` along it, `depth` away from it, its near edge `distance`
  // from the route.
  struct Footprint {
    double along = 0.0;
    double length = 1.0;
    double distance = 0.0;
    double depth = 1.0;
  };

  // `route_start`: the arc length along `road` where the driven route begins (the road runs on behind it).
  Roadside(const Centerline& road, const GroundSurface& ground, uint64_t seed, double route_start);

  double routeStart() const { return route_start_; }

  // Calls furnish(lot, rng) for consecutive lots along each side of the route, their lengths drawn
  // by lot_length. A lot is skipped where its frontage (the line `frontage` metres out) runs where a
  // lot of this same pass already stood.
  void forEachLot(double frontage, const std::function<double(Rng&)>& lot_length,
                  const std::function<void(const Lot&, Rng&)>& furnish);

  // Each add* places nothing and returns false where the shape would come nearer than `clearance` to
  // the route (poles, trees and bushes: where their centre would). A block stands on the ground (its base sunk into slopes) unless `lift` raises its
  // underside above the ground.
  bool addBlock(const Lot& lot, const Footprint& footprint, double height, float reflectivity, double clearance,
                double lift = 0.0, std::optional<WindowGrid> windows = std::nullopt);
  // A car centred `distance` out; `yaw` turns it from the road's direction (pi/2: parked across).
  bool addCar(const Lot& lot, double along, double distance, double yaw, Rng& rng, double clearance);
  // A pole centred `distance` out, with an arm reaching `arm` metres back over the road at its top.
  bool addPole(const Lot& lot, double along, double distance, double radius, double height, double arm,
               double clearance);
  bool addTree(const Lot& lot, double along, double distance, Rng& rng, double clearance);
  bool addBush(const Lot& lot, double along, double distance, Rng& rng, double clearance);

  std::vector<Primitive> takePrimitives() { return std::move(primitives_); }

 private:
  struct Placement {
    Eigen::Vector2d point;  // on the ground plane
    double heading;         // of the road there
    Eigen::Vector2d outward;  // unit, away from the route on the lot's side
  };
  Placement place(const Lot& lot, double along, double distance) const;
  bool clearOfRoad(const Eigen::Vector2d& point, double clearance) const;
  bool footprintClear(const std::vector<Eigen::Vector2d>& corners, double clearance) const;
  double groundAt(const Eigen::Vector2d& point) const { return ground_.height(point.x(), point.y()); }

  const Centerline& road_;
  const GroundSurface& ground_;
  uint64_t seed_;
  double route_start_;
  int pass_ = 0;  // forEachLot calls so far: each draws its own random streams
  std::vector<Primitive> primitives_;
};

}  // namespace elo::sim
