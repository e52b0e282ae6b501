// Localization: a saved map rendered into the images of a model (the non-ground range image and the
// ground BEV map), as a model fused from scans at that pose would hold them, so that the scan's features
// register against the map with the odometry's own association and cost.
#include "core/common/map_render.hpp"
#include "core/common/normals.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"
#include "elo/map/point_map.hpp"

namespace elo::cpu {

void renderMapModel(const MapCloud& map, const std::vector<int32_t>& points, const Rigid3f& sensor_from_map,
                    const SphericalProjection& spherical, const BevProjection& bev, const MapRendering& rendering,
                    MapRenderScratch& scratch, Model& model) {
  const size_t count = points.size();
  scratch.vertex.resize(count);
  scratch.normal.resize(count);
  std::vector<GroundOffer>& offers = scratch.ground.offers;
  offers.resize(count);
  scratch.closest.setSingleWriter(runsAlone());
  parallelFor(count, [&](size_t i) {
    const int32_t index = points[i];
    const Float3 vertex = sensor_from_map.apply(toFloat3(map.points[index]));
    const Float3 normal = sensor_from_map.rotate(toFloat3(map.normals[index]));
    scratch.vertex[i] = vertex;
    scratch.normal[i] = towardsSensor(normal, vertex);
    offers[i].cell = -1;
    if (isMapGround(vertex, normal, rendering)) {
      int row = 0;
      int col = 0;
      if (bev.cellOf(vertex, row, col)) {
        offers[i] = GroundOffer(row * bev.cols + col, toVec3f(vertex), mapGroundAge(vertex, rendering),
                                static_cast<uint32_t>(i));
      }
      return;
    }
    if (isZero(normal)) return;
    int row = 0;
    int col = 0;
    if (!spherical.pixelOf(vertex, row, col)) return;
    const float range = norm(vertex);
    const uint32_t source = static_cast<uint32_t>(i);
    forEachSplatPixel(spherical, row, col, range, rendering.splat_radius,
                      [&](int pixel) { scratch.closest.offer(static_cast<size_t>(pixel), range, source); });
  });
  SphericalImage& image = model.nonground;
  parallelFor(image.pixelCount(), [&](size_t pixel) {
    const ClosestKey key = scratch.closest.take(pixel);
    if (key == kNoClosestKey) {
      image.range[pixel] = 0.0f;
      image.normal[pixel].setZero();
      return;
    }
    const uint32_t source = closestWinsSource(key);
    image.vertex[pixel] = toVec3f(scratch.vertex[source]);
    image.normal[pixel] = toVec3f(scratch.normal[source]);
    image.range[pixel] = closestWinsRange(key);
    image.stamp[pixel] = 0.0f;
  });
  fillGroundMap(rendering.same_surface_distance, scratch.ground, model.ground);
  model.initialized = true;
}

}  // namespace elo::cpu
