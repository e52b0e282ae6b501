// The road the vehicle drives along: the route's path as a polyline. Worlds shape the ground across it
// (crown, kerbs, ditches) and keep their objects clear of it, so the distance from any point to it
// is answered through a grid of nearby segments.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "elo/sim/grid_walk.hpp"

namespace elo::sim {

class Centerline {
 public:
  struct Frame {
    Eigen::Vector2d point;
    Eigen::Vector2d tangent;  // unit, the direction of travel
    Eigen::Vector2d left;     // unit, tangent turned by +90 deg
    double heading = 0.0;     // of the tangent (rad)
  };

  // Distances beyond `reach` are reported as `reach`: nothing farther depends on the road.
  Centerline(const std::vector<Eigen::Vector2d>& points, double reach);

  double distance(const Eigen::Vector2d& point) const;
  double length() const { return arc_length_.back(); }
  double reach() const { return reach_; }
  // Position and direction at an arc length, clamped to [0, length()].
  Frame frameAt(double arc_length) const;
  const std::vector<Eigen::Vector2d>& points() const { return points_; }

 private:
  void buildGrid();
  double segmentDistance(size_t segment, const Eigen::Vector2d& point) const;

  std::vector<Eigen::Vector2d> points_;
  std::vector<double> arc_length_;  // at each point
  double reach_;
  GridGeometry grid_;
  std::vector<uint32_t> cell_begin_;     // compressed rows of the segments within reach of each cell
  std::vector<uint32_t> cell_segments_;
};

}  // namespace elo::sim
