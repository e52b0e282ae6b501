// Static geometry rays are cast against: a ground surface and analytic primitives, the primitives
// found through a uniform 2D grid over x-y.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "elo/sim/grid_walk.hpp"
#include "elo/sim/ground.hpp"
#include "elo/sim/primitives.hpp"

namespace elo::sim {

enum class SurfaceKind : uint8_t { ground, object, moving_object, foliage };

struct Hit {
  double distance = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  float reflectivity = 0.0f;
  SurfaceKind kind = SurfaceKind::ground;
};

// Anything a LiDAR can scan: a static scene, or a world at one instant.
class RayCaster {
 public:
  virtual ~RayCaster() = default;
  // The nearest surface along the ray within max_distance.
  virtual std::optional<Hit> cast(const Ray& ray, double max_distance) const = 0;
};

class Scene : public RayCaster {
 public:
  // `ground` may be null (a scene of primitives only). `cell_size` is the grid's cell side (m).
  Scene(std::shared_ptr<const GroundSurface> ground, std::vector<Primitive> primitives,
        float ground_reflectivity = 0.15f, double cell_size = 4.0);

  std::optional<Hit> cast(const Ray& ray, double max_distance) const override;

  const GroundSurface* ground() const { return ground_.get(); }
  const std::vector<Primitive>& primitives() const { return primitives_; }

 private:
  void buildGrid(double cell_size);
  std::optional<Hit> castPrimitives(const Ray& ray, double max_distance) const;

  std::shared_ptr<const GroundSurface> ground_;
  std::vector<Primitive> primitives_;
  float ground_reflectivity_;
  GridGeometry grid_;
  // Compressed rows: cell c lists cell_items_[cell_begin_[c] .. cell_begin_[c + 1]).
  std::vector<uint32_t> cell_begin_;
  std::vector<uint32_t> cell_items_;
  std::vector<float> cell_bottom_;  // lowest and highest z of the cell's primitives, so that a ray
  std::vector<float> cell_top_;     // passing above or below all of them skips the cell
};

// Casts against `primitives` by testing each one (the few moving objects of a frame); the nearest hit
// closer than max_distance, if any.
std::optional<Hit> castEach(const Ray& ray, const std::vector<Primitive>& primitives, double max_distance,
                            SurfaceKind kind);

}  // namespace elo::sim
