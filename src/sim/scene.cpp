#include "elo/sim/scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace elo::sim {

Scene::Scene(std::shared_ptr<const GroundSurface> ground, std::vector<Primitive> primitives,
             float ground_reflectivity, double cell_size)
    : ground_(std::move(ground)), primitives_(std::move(primitives)), ground_reflectivity_(ground_reflectivity) {
  buildGrid(cell_size);
}

void Scene::buildGrid(double cell_size) {
  grid_.cell_size = cell_size;
  cell_begin_.assign(1, 0);
  if (primitives_.empty()) return;
  std::vector<Bounds3> boxes;
  boxes.reserve(primitives_.size());
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  for (const Primitive& primitive : primitives_) {
    boxes.push_back(bounds(primitive.shape));
    low = low.cwiseMin(boxes.back().min.head<2>());
    high = high.cwiseMax(boxes.back().max.head<2>());
  }
  grid_.origin_x = low.x();
  grid_.origin_y = low.y();
  grid_.cols = std::max(1, static_cast<int>(std::ceil((high.x() - low.x()) / cell_size)));
  grid_.rows = std::max(1, static_cast<int>(std::ceil((high.y() - low.y()) / cell_size)));
  const size_t cells = static_cast<size_t>(grid_.cols) * grid_.rows;

  const auto cellRange = [&](const Bounds3& box, int& col0, int& col1, int& row0, int& row1) {
    col0 = std::clamp(static_cast<int>((box.min.x() - grid_.origin_x) / cell_size), 0, grid_.cols - 1);
    col1 = std::clamp(static_cast<int>((box.max.x() - grid_.origin_x) / cell_size), 0, grid_.cols - 1);
    row0 = std::clamp(static_cast<int>((box.min.y() - grid_.origin_y) / cell_size), 0, grid_.rows - 1);
    row1 = std::clamp(static_cast<int>((box.max.y() - grid_.origin_y) / cell_size), 0, grid_.rows - 1);
  };
  // Two passes (count, then fill) build the compressed rows without per-cell vectors.
  std::vector<uint32_t> counts(cells, 0);
  cell_bottom_.assign(cells, std::numeric_limits<float>::infinity());
  cell_top_.assign(cells, -std::numeric_limits<float>::infinity());
  for (const Bounds3& box : boxes) {
    int col0, col1, row0, row1;
    cellRange(box, col0, col1, row0, row1);
    for (int row = row0; row <= row1; ++row) {
      for (int col = col0; col <= col1; ++col) {
        const size_t cell = static_cast<size_t>(row) * grid_.cols + col;
        ++counts[cell];
        cell_bottom_[cell] = std::min(cell_bottom_[cell], static_cast<float>(box.min.z()));
        cell_top_[cell] = std::max(cell_top_[cell], static_cast<float>(box.max.z()));
      }
    }
  }
  cell_begin_.assign(cells + 1, 0);
  for (size_t cell = 0; cell < cells; ++cell) cell_begin_[cell + 1] = cell_begin_[cell] + counts[cell];
  cell_items_.resize(cell_begin_.back());
  std::vector<uint32_t> fill(cell_begin_.begin(), cell_begin_.end() - 1);
  for (uint32_t index = 0; index < boxes.size(); ++index) {
    int col0, col1, row0, row1;
    cellRange(boxes[index], col0, col1, row0, row1);
    for (int row = row0; row <= row1; ++row) {
      for (int col = col0; col <= col1; ++col) {
        cell_items_[fill[static_cast<size_t>(row) * grid_.cols + col]++] = index;
      }
    }
  }
}

std::optional<Hit> Scene::cast(const Ray& ray, double max_distance) const {
  std::optional<Hit> best;
  if (ground_) {
    if (const auto distance = ground_->intersect(ray, 0.0, max_distance)) {
      const Eigen::Vector3d point = ray.at(*distance);
      best = Hit{*distance, ground_->normal(point.x(), point.y()), ground_reflectivity_, SurfaceKind::ground};
      max_distance = *distance;
    }
  }
  if (auto object = castPrimitives(ray, max_distance)) best = object;
  return best;
}

std::optional<Hit> Scene::castPrimitives(const Ray& ray, double max_distance) const {
  if (primitives_.empty()) return std::nullopt;
  std::optional<Hit> best;
  double nearest = max_distance;
  walkGrid(grid_, ray, 0.0, max_distance, [&](int col, int row, double entry, double exit) {
    const size_t cell = static_cast<size_t>(row) * grid_.cols + col;
    const double z_entry = ray.origin.z() + entry * ray.direction.z();
    const double z_exit = ray.origin.z() + exit * ray.direction.z();
    if (std::min(z_entry, z_exit) > cell_top_[cell] || std::max(z_entry, z_exit) < cell_bottom_[cell]) {
      return true;
    }
    for (uint32_t item = cell_begin_[cell]; item < cell_begin_[cell + 1]; ++item) {
      const Primitive& primitive = primitives_[cell_items_[item]];
      if (const auto hit = intersect(ray, primitive.shape, 0.0, nearest)) {
        nearest = hit->distance;
        best = Hit{hit->distance, hit->normal, reflectivityAt(primitive, ray.at(hit->distance), hit->normal),
                   primitive.foliage ? SurfaceKind::foliage : SurfaceKind::object};
      }
    }
    // A hit inside this cell cannot be beaten by anything in a farther cell.
    return !(best && best->distance <= exit);
  });
  return best;
}

std::optional<Hit> castEach(const Ray& ray, const std::vector<Primitive>& primitives, double max_distance,
                            SurfaceKind kind) {
  std::optional<Hit> best;
  for (const Primitive& primitive : primitives) {
    if (const auto hit = intersect(ray, primitive.shape, 0.0, max_distance)) {
      max_distance = hit->distance;
      best = Hit{hit->distance, hit->normal, reflectivityAt(primitive, ray.at(hit->distance), hit->normal), kind};
    }
  }
  return best;
}

}  // namespace elo::sim
