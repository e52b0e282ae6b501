#include "worlds/roadside.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace elo::sim {
namespace {

constexpr double kEmbedding = 0.3;        // m a standing block reaches below its lowest corner's ground
constexpr double kFrontageSpacing = 2.0;  // m between the frontage points that record a furnished lot
constexpr double kRevisitRadius = 3.0;    // m: a frontage point this close to an earlier one is revisited,
constexpr double kRevisitArc = 2.0 * kRevisitRadius;  // m: when the road beside them is this far apart
constexpr double kEdgeSampling = 1.0;     // m between the footprint points checked against the route

// A point of a lot's frontage line and the road's arc length beside it.
struct FrontagePoint {
  Eigen::Vector2d point;
  double arc;
};

// Frontage points of the lots furnished so far, hashed by cell for the revisit test. A revisit is the
// road coming back past a place: an earlier point close by that stands beside another stretch of the
// road. The lot just before shares its end with this one's start; that is no revisit.
class FrontageIndex {
 public:
  bool mostlyRevisited(const std::vector<FrontagePoint>& points) const {
    size_t revisited = 0;
    for (const FrontagePoint& point : points) revisited += isRevisit(point) ? 1 : 0;
    return 2 * revisited > points.size();
  }

  void add(const std::vector<FrontagePoint>& points) {
    for (const FrontagePoint& point : points) {
      cells_[key(cellOf(point.point.x()), cellOf(point.point.y()))].push_back(point);
    }
  }

 private:
  static int64_t cellOf(double coordinate) { return static_cast<int64_t>(std::floor(coordinate / kRevisitRadius)); }
  static int64_t key(int64_t col, int64_t row) { return col * 0x100000000LL + row; }

  bool isRevisit(const FrontagePoint& point) const {
    const int64_t col = cellOf(point.point.x());
    const int64_t row = cellOf(point.point.y());
    for (int64_t dc = -1; dc <= 1; ++dc) {
      for (int64_t dr = -1; dr <= 1; ++dr) {
        const auto cell = cells_.find(key(col + dc, row + dr));
        if (cell == cells_.end()) continue;
        for (const FrontagePoint& other : cell->second) {
          const bool close = (other.point - point.point).squaredNorm() < kRevisitRadius * kRevisitRadius;
          if (close && std::abs(other.arc - point.arc) > kRevisitArc) return true;
        }
      }
    }
    return false;
  }

  std::unordered_map<int64_t, std::vector<FrontagePoint>> cells_;
};

std::vector<Eigen::Vector2d> rectangle(const Eigen::Vector2d& center, double heading, double length, double width) {
  const Eigen::Vector2d along = 0.5 * length * Eigen::Vector2d(std::cos(heading), std::sin(heading));
  const Eigen::Vector2d across = 0.5 * width * Eigen::Vector2d(-std::sin(heading), std::cos(heading));
  return {center + along + across, center - along + across, center - along - across, center + along - across};
}

}  // namespace

Roadside::Roadside(const Centerline& road, const GroundSurface& ground, uint64_t seed, double route_start)
    : road_(road), ground_(ground), seed_(seed), route_start_(route_start) {}

void Roadside::forEachLot(double frontage, const std::function<double(Rng&)>& lot_length,
                          const std::function<void(const Lot&, Rng&)>& furnish) {
  const int pass = pass_++;
  FrontageIndex furnished;
  for (const double side : {1.0, -1.0}) {
    const uint64_t side_id = side > 0.0 ? 1 : 2;
    Rng lengths(mixSeed(seed_, static_cast<uint64_t>(pass), side_id));
    int index = 0;
    for (double begin = 0.0; begin < road_.length(); ++index) {
      const Lot lot{begin, std::max(lot_length(lengths), 0.5), side, index};
      begin += lot.length;
      std::vector<FrontagePoint> points;
      for (double along = 0.0; along <= lot.length; along += kFrontageSpacing) {
        points.push_back({place(lot, along, frontage).point, lot.begin + along});
      }
      if (furnished.mostlyRevisited(points)) continue;
      furnished.add(points);
      Rng rng(mixSeed(seed_, static_cast<uint64_t>(pass), side_id, static_cast<uint64_t>(index)));
      furnish(lot, rng);
    }
  }
}

Roadside::Placement Roadside::place(const Lot& lot, double along, double distance) const {
  const Centerline::Frame frame = road_.frameAt(lot.begin + along);
  const Eigen::Vector2d outward = lot.side * frame.left;
  return {frame.point + distance * outward, frame.heading, outward};
}

bool Roadside::clearOfRoad(const Eigen::Vector2d& point, double clearance) const {
  return road_.distance(point) >= clearance;
}

bool Roadside::footprintClear(const std::vector<Eigen::Vector2d>& corners, double clearance) const {
  for (size_t i = 0; i < corners.size(); ++i) {
    const Eigen::Vector2d& a = corners[i];
    const Eigen::Vector2d& b = corners[(i + 1) % corners.size()];
    const int samples = std::max(1, static_cast<int>(std::ceil((b - a).norm() / kEdgeSampling)));
    for (int k = 0; k < samples; ++k) {
      if (!clearOfRoad(a + (b - a) * (static_cast<double>(k) / samples), clearance)) return false;
    }
  }
  return true;
}

bool Roadside::addBlock(const Lot& lot, const Footprint& footprint, double height, float reflectivity,
                        double clearance, double lift, std::optional<WindowGrid> windows) {
  const Placement center = place(lot, footprint.along + 0.5 * footprint.length,
                                 footprint.distance + 0.5 * footprint.depth);
  const std::vector<Eigen::Vector2d> corners = rectangle(center.point, center.heading, footprint.length, footprint.depth);
  if (!footprintClear(corners, clearance)) return false;
  double lowest = groundAt(center.point);
  for (const Eigen::Vector2d& corner : corners) lowest = std::min(lowest, groundAt(corner));
  const double base = groundAt(center.point);
  const double bottom = lift > 0.0 ? base + lift : lowest - kEmbedding;
  const double top = base + lift + height;
  primitives_.push_back({uprightBox(Eigen::Vector3d(center.point.x(), center.point.y(), 0.5 * (bottom + top)),
                                    Eigen::Vector3d(footprint.length, footprint.depth, top - bottom), center.heading),
                         reflectivity, windows});
  return true;
}

bool Roadside::addCar(const Lot& lot, double along, double distance, double yaw, Rng& rng, double clearance) {
  const Placement at = place(lot, along, distance);
  const CarBody body = CarBody::random(rng);
  const double heading = at.heading + yaw;
  if (!footprintClear(rectangle(at.point, heading, body.length, body.width), clearance)) return false;
  elo::sim::addCar(primitives_, at.point, heading, groundAt(at.point), body);
  return true;
}

bool Roadside::addPole(const Lot& lot, double along, double distance, double radius, double height, double arm,
                       double clearance) {
  const Placement at = place(lot, along, distance);
  if (!clearOfRoad(at.point, clearance)) return false;
  const double ground = groundAt(at.point);
  primitives_.push_back({VerticalCylinder{at.point, radius, ground - kEmbedding, ground + height}, 0.5f});
  if (arm > 0.0) {
    const Eigen::Vector2d middle = at.point - 0.5 * arm * at.outward;
    const double arm_heading = std::atan2(at.outward.y(), at.outward.x());
    primitives_.push_back({uprightBox(Eigen::Vector3d(middle.x(), middle.y(), ground + height - 0.1),
                                      Eigen::Vector3d(arm, 0.2, 0.15), arm_heading),
                           0.6f});
  }
  return true;
}

bool Roadside::addTree(const Lot& lot, double along, double distance, Rng& rng, double clearance) {
  const Placement at = place(lot, along, distance);
  if (!clearOfRoad(at.point, clearance)) return false;
  elo::sim::addTree(primitives_, at.point, groundAt(at.point), rng);
  return true;
}

bool Roadside::addBush(const Lot& lot, double along, double distance, Rng& rng, double clearance) {
  const Placement at = place(lot, along, distance);
  if (!clearOfRoad(at.point, clearance)) return false;
  elo::sim::addBush(primitives_, at.point, groundAt(at.point), rng);
  return true;
}

}  // namespace elo::sim
