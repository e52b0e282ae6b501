// Sec. III-C.2: the bird's-eye-view map of ground points, and the normals of the BEV model fitted to
// the model points nearest an associated cell (groundNormal() of association.hpp, shared with the CUDA
// backend).
#include "core/common/association.hpp"
#include "core/common/eigen_interop.hpp"
#include "core/cpu/image_views.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

std::vector<int32_t> groundPixels(const ScanImage& scan) {
  std::vector<int32_t> pixels;
  parallelSelect(scan.label.size(), [&](size_t pixel) { return scan.label[pixel] == PixelLabel::ground; }, pixels);
  return pixels;
}

// Each ground pixel's cell is found once, as it is offered; a pixel outside the map offers to cell -1,
// which fillGroundMap() passes over, so the offers to cells come in the pixels' order.
void buildGroundMap(const ScanImage& scan, const std::vector<int32_t>& ground_pixels, const BevProjection& projection,
                    float same_surface_distance, GroundMapScratch& scratch, BevImage& ground) {
  const SphericalImage& image = scan.image;
  std::vector<GroundOffer>& offers = scratch.offers;
  offers.resize(ground_pixels.size());
  parallelFor(ground_pixels.size(), [&](size_t i) {
    const int32_t pixel = ground_pixels[i];
    GroundOffer& offer = offers[i];
    offer.vertex = image.vertex[pixel];
    int row = 0;
    int col = 0;
    offer.cell = projection.cellOf(offer.vertex, row, col) ? row * projection.cols + col : -1;
    offer.range = image.range[pixel];  // the norm of the vertex, as GroundOffer's constructor computes it
    offer.stamp = image.stamp[pixel];
    offer.source = static_cast<uint32_t>(pixel);
  });
  fillGroundMap(same_surface_distance, scratch, ground);
}

namespace {

// How many offers ahead the serial fill asks for a grid cell. The grid (millions of cells) is far larger
// than the caches and the offers visit it nearly at random, so each lookup would wait for memory; asked
// this far ahead, the cell is in the cache when its offer comes.
constexpr size_t kCellPrefetchDistance = 48;

}  // namespace

void fillGroundMap(float same_surface_distance, GroundMapScratch& scratch, BevImage& map) {
  const std::vector<GroundOffer>& offers = scratch.offers;
  map.clear();
  // Round 1: the closest offer's range per cell. A cell takes the next slot at its first offer.
  std::vector<int32_t>& slot_of_offer = scratch.slot_of_offer;
  slot_of_offer.resize(offers.size());
  for (size_t i = 0; i < offers.size(); ++i) {
    if (i + kCellPrefetchDistance < offers.size()) {
      const int32_t ahead = offers[i + kCellPrefetchDistance].cell;
      if (ahead >= 0) __builtin_prefetch(&map.point_of_cell[ahead], 1);
    }
    const GroundOffer& offer = offers[i];
    if (offer.cell < 0) continue;
    int32_t& slot = map.point_of_cell[offer.cell];
    if (slot < 0) {
      slot = static_cast<int32_t>(map.cell.size());
      map.cell.push_back(offer.cell);
      map.range.push_back(offer.range);
    } else if (offer.range < map.range[slot]) {
      map.range[slot] = offer.range;
    }
    slot_of_offer[i] = slot;
  }
  // Round 2: the oldest offer on that surface.
  const size_t slots = map.cell.size();
  std::vector<ClosestKey>& oldest = scratch.oldest;
  std::vector<int32_t>& winner = scratch.winner;
  oldest.assign(slots, kNoClosestKey);
  winner.resize(slots);
  for (size_t i = 0; i < offers.size(); ++i) {
    const GroundOffer& offer = offers[i];
    if (offer.cell < 0) continue;
    const int32_t slot = slot_of_offer[i];
    if (!onClosestSurface(offer.range, map.range[slot], same_surface_distance)) continue;
    const ClosestKey key = oldestWinsKey(offer.stamp, offer.source);
    if (key < oldest[slot]) {
      oldest[slot] = key;
      winner[slot] = static_cast<int32_t>(i);
    }
  }
  map.vertex.resize(slots);
  map.stamp.resize(slots);
  parallelFor(slots, [&](size_t slot) {
    const GroundOffer& offer = offers[winner[slot]];
    map.vertex[slot] = offer.vertex;
    map.range[slot] = offer.range;
    map.stamp[slot] = offer.stamp;
  });
}

void GroundNormalCache::reset(size_t points) {
  if (points > capacity_) {
    capacity_ = points + points / 2;
    normals_.resize(capacity_);
    states_ = std::make_unique<std::atomic<uint8_t>[]>(capacity_);
  }
  for (size_t i = 0; i < points; ++i) states_[i].store(unknown, std::memory_order_relaxed);
}

Vec3f GroundNormalCache::normal(const BevImage& model, const BevProjection& projection, const BevConfig& config,
                                int32_t point) {
  if (states_[point].load(std::memory_order_acquire) == fitted) return normals_[point];
  const Vec3f normal =
      toVec3f(groundNormal(GroundPoints(model), projection, point, config.normal_neighbours, config.normal_patch_radius));
  uint8_t expected = unknown;
  if (states_[point].compare_exchange_strong(expected, fitting, std::memory_order_acq_rel)) {
    normals_[point] = normal;
    states_[point].store(fitted, std::memory_order_release);
  }
  return normal;
}

}  // namespace elo::cpu
