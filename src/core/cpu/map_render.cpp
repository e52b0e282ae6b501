// Localization: a saved map rendered into the images of a model (the non-ground range image and the
// ground BEV map), as a model fused from scans at that pose would hold them, so that the scan's features
// register against the map with the odometry's own association and cost.
#include <algorithm>
#include <cmath>

#include "core/common/normals.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"
#include "elo/localization/point_map.hpp"

namespace elo::cpu {

namespace {

// A map point's disc covers at most this many pixels either side of its own (a point closer than the
// splat radius allows would otherwise fill the image).
constexpr int kMaxSplatColumns = 4;
constexpr int kMaxSplatRows = 2;
// A point in the ground band is ground unless its normal leans more than about 25 degrees.
constexpr float kMinGroundNormalZ = 0.9f;

bool isGround(const Float3& point, const Float3& normal, const MapRendering& rendering) {
  if (!(point.z >= rendering.ground_low && point.z <= rendering.ground_high)) return false;
  return isZero(normal) || std::fabs(normal.z) >= kMinGroundNormalZ;
}

// Offers the point (listed `source`) at (row, col) and range `range` to every pixel its disc spans.
void splat(const SphericalProjection& projection, int row, int col, float range, float splat_radius, uint32_t source,
           ClosestWins& closest) {
  const float angle = splat_radius / range;
  const float column_angle = 2.0f * static_cast<float>(M_PI) / static_cast<float>(projection.cols);
  const float row_angle = projection.fov_span / static_cast<float>(projection.rows);
  const int columns = std::min(kMaxSplatColumns, static_cast<int>(angle / column_angle));
  const int rows = std::min(kMaxSplatRows, static_cast<int>(angle / row_angle));
  for (int r = std::max(0, row - rows); r <= std::min(projection.rows - 1, row + rows); ++r) {
    for (int dc = -columns; dc <= columns; ++dc) {
      int c = col + dc;
      if (c < 0) c += projection.cols;
      if (c >= projection.cols) c -= projection.cols;
      closest.offer(static_cast<size_t>(r) * projection.cols + c, range, source);
    }
  }
}

}  // namespace

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
    if (isGround(vertex, normal, rendering)) {
      int row = 0;
      int col = 0;
      // A map has no observation times: the height above the band's floor stands in for the age, so that
      // of the points on one surface in a cell (the fill's second round) the lowest, the ground rather
      // than a wall's foot, wins, whatever the tie-break among equal ages would pick.
      if (bev.cellOf(vertex, row, col)) {
        offers[i] = GroundOffer(row * bev.cols + col, toVec3f(vertex), vertex.z - rendering.ground_low, static_cast<uint32_t>(i));
      }
      return;
    }
    if (isZero(normal)) return;
    int row = 0;
    int col = 0;
    if (!spherical.pixelOf(vertex, row, col)) return;
    splat(spherical, row, col, norm(vertex), rendering.splat_radius, static_cast<uint32_t>(i), scratch.closest);
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
