#include "elo/sim/centerline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace elo::sim {
namespace {
constexpr double kCellSize = 4.0;  // m
}  // namespace

Centerline::Centerline(const std::vector<Eigen::Vector2d>& points, double reach) : reach_(reach) {
  for (const Eigen::Vector2d& point : points) {
    if (points_.empty() || (point - points_.back()).norm() > 1e-3) points_.push_back(point);
  }
  if (points_.empty()) throw std::invalid_argument("Centerline needs at least one point");
  if (points_.size() == 1) points_.push_back(points_.front() + Eigen::Vector2d(1e-3, 0.0));
  arc_length_.assign(1, 0.0);
  for (size_t i = 1; i < points_.size(); ++i) {
    arc_length_.push_back(arc_length_.back() + (points_[i] - points_[i - 1]).norm());
  }
  buildGrid();
}

void Centerline::buildGrid() {
  Eigen::Vector2d low = points_.front();
  Eigen::Vector2d high = points_.front();
  for (const Eigen::Vector2d& point : points_) {
    low = low.cwiseMin(point);
    high = high.cwiseMax(point);
  }
  // A query scans one cell's list: the segments within reach of any point of the cell.
  grid_.cell_size = kCellSize;
  grid_.origin_x = low.x() - reach_;
  grid_.origin_y = low.y() - reach_;
  grid_.cols = static_cast<int>(std::ceil((high.x() - low.x() + 2.0 * reach_) / grid_.cell_size)) + 1;
  grid_.rows = static_cast<int>(std::ceil((high.y() - low.y() + 2.0 * reach_) / grid_.cell_size)) + 1;

  const auto forEachCell = [&](size_t segment, auto&& action) {
    const Eigen::Vector2d a = points_[segment].cwiseMin(points_[segment + 1]) - Eigen::Vector2d::Constant(reach_);
    const Eigen::Vector2d b = points_[segment].cwiseMax(points_[segment + 1]) + Eigen::Vector2d::Constant(reach_);
    const int col0 = std::max(0, static_cast<int>((a.x() - grid_.origin_x) / grid_.cell_size));
    const int col1 = std::min(grid_.cols - 1, static_cast<int>((b.x() - grid_.origin_x) / grid_.cell_size));
    const int row0 = std::max(0, static_cast<int>((a.y() - grid_.origin_y) / grid_.cell_size));
    const int row1 = std::min(grid_.rows - 1, static_cast<int>((b.y() - grid_.origin_y) / grid_.cell_size));
    for (int row = row0; row <= row1; ++row) {
      for (int col = col0; col <= col1; ++col) action(static_cast<size_t>(row) * grid_.cols + col);
    }
  };
  const size_t cells = static_cast<size_t>(grid_.cols) * grid_.rows;
  std::vector<uint32_t> counts(cells, 0);
  for (size_t segment = 0; segment + 1 < points_.size(); ++segment) {
    forEachCell(segment, [&](size_t cell) { ++counts[cell]; });
  }
  cell_begin_.assign(cells + 1, 0);
  for (size_t cell = 0; cell < cells; ++cell) cell_begin_[cell + 1] = cell_begin_[cell] + counts[cell];
  cell_segments_.resize(cell_begin_.back());
  std::vector<uint32_t> fill(cell_begin_.begin(), cell_begin_.end() - 1);
  for (size_t segment = 0; segment + 1 < points_.size(); ++segment) {
    forEachCell(segment, [&](size_t cell) { cell_segments_[fill[cell]++] = static_cast<uint32_t>(segment); });
  }
}

double Centerline::segmentDistance(size_t segment, const Eigen::Vector2d& point) const {
  const Eigen::Vector2d& a = points_[segment];
  const Eigen::Vector2d along = points_[segment + 1] - a;
  const double fraction = std::clamp((point - a).dot(along) / along.squaredNorm(), 0.0, 1.0);
  return (a + fraction * along - point).norm();
}

double Centerline::distance(const Eigen::Vector2d& point) const {
  const double col = std::floor((point.x() - grid_.origin_x) / grid_.cell_size);
  const double row = std::floor((point.y() - grid_.origin_y) / grid_.cell_size);
  if (!(col >= 0.0 && row >= 0.0 && col < grid_.cols && row < grid_.rows)) return reach_;
  const size_t cell = static_cast<size_t>(row) * grid_.cols + static_cast<size_t>(col);
  double nearest = reach_;
  for (uint32_t item = cell_begin_[cell]; item < cell_begin_[cell + 1]; ++item) {
    nearest = std::min(nearest, segmentDistance(cell_segments_[item], point));
  }
  return nearest;
}

Centerline::Frame Centerline::frameAt(double arc_length) const {
  const double clamped = std::clamp(arc_length, 0.0, length());
  const size_t upper = std::upper_bound(arc_length_.begin(), arc_length_.end(), clamped) - arc_length_.begin();
  const size_t segment = std::min(upper == 0 ? 0 : upper - 1, points_.size() - 2);
  const Eigen::Vector2d along = points_[segment + 1] - points_[segment];
  const double segment_length = arc_length_[segment + 1] - arc_length_[segment];
  Frame frame;
  frame.tangent = along / segment_length;
  frame.point = points_[segment] + (clamped - arc_length_[segment]) * frame.tangent;
  frame.left = Eigen::Vector2d(-frame.tangent.y(), frame.tangent.x());
  frame.heading = std::atan2(frame.tangent.y(), frame.tangent.x());
  return frame;
}

}  // namespace elo::sim
