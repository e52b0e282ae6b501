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

// How many elements ahead the fill's loops ask for a grid cell. The grid (millions of cells) is far
// larger than the caches and the offers visit it nearly at random, so each lookup would wait for memory;
// asked this far ahead, the cell is in the cache when its element comes.
constexpr size_t kCellPrefetchDistance = 48;

// Runs `body(i)` for i in [begin, end) in order, asking `cell_of(i + kCellPrefetchDistance)`'s grid entry
// ahead (cells < 0 are none).
template <typename CellOf, typename Body>
void prefetchingCells(size_t begin, size_t end, std::vector<int32_t>& grid, const CellOf& cell_of, const Body& body) {
  for (size_t i = begin; i < end; ++i) {
    if (i + kCellPrefetchDistance < end) {
      const int32_t ahead = cell_of(i + kCellPrefetchDistance);
      if (ahead >= 0) __builtin_prefetch(&grid[ahead], 1);
    }
    body(i);
  }
}

// The same over [0, count), in parallel.
template <typename CellOf, typename Body>
void forEachPrefetchingCells(size_t count, std::vector<int32_t>& grid, const CellOf& cell_of, const Body& body) {
  parallelForBlocks(count, [&](size_t begin, size_t end) { prefetchingCells(begin, end, grid, cell_of, body); });
}

// BevImage::clear() across the threads: each point's cell is emptied, so the cost is the point count.
void takeOffGrid(BevImage& map) {
  forEachPrefetchingCells(
      map.cell.size(), map.point_of_cell, [&](size_t point) { return map.cell[point]; },
      [&](size_t point) { map.point_of_cell[map.cell[point]] = -1; });
  map.cell.clear();
  map.vertex.clear();
  map.range.clear();
  map.stamp.clear();
}

// The grid entry as unsigned, so that "empty" (-1) is the largest value and the smallest offer index kept
// in it is the cell's first offer. Signed and unsigned views of one integer may alias.
uint32_t& asUnsigned(int32_t& entry) { return reinterpret_cast<uint32_t&>(entry); }

// Sizes the per-slot arrays of the map and the rounds once the slot count is known.
void sizeSlots(size_t slots, GroundMapScratch& scratch, BevImage& map) {
  scratch.closest.resize(slots);
  scratch.oldest.assign(slots, kNoClosestKey);
  map.cell.resize(slots);
  map.vertex.resize(slots);
  map.range.resize(slots);
  map.stamp.resize(slots);
}

// The slots and round 1 on one thread, in one sweep over the offers: a cell takes the next slot at its
// first offer. The grid is visited once per offer.
void slotsAndClosestAlone(const std::vector<GroundOffer>& offers, GroundMapScratch& scratch, BevImage& map) {
  std::vector<int32_t>& slot_of_offer = scratch.slot_of_offer;
  std::vector<ClosestKey>& closest = scratch.closest;
  slot_of_offer.resize(offers.size());
  closest.clear();
  prefetchingCells(
      0, offers.size(), map.point_of_cell, [&](size_t i) { return offers[i].cell; },
      [&](size_t i) {
        const GroundOffer& offer = offers[i];
        if (offer.cell < 0) return;
        int32_t& slot = map.point_of_cell[offer.cell];
        if (slot < 0) {
          slot = static_cast<int32_t>(map.cell.size());
          map.cell.push_back(offer.cell);
          closest.push_back(kNoClosestKey);
        }
        slot_of_offer[i] = slot;
        keepSmaller(closest[slot], closestWinsKey(offer.range, offer.source), true);
      });
  sizeSlots(map.cell.size(), scratch, map);
}

// The same across threads. Each cell's first offer is the smallest offer index, kept by a minimum in the
// emptied grid and read back per offer; a cell's slot is the number of first offers before its own. The
// grid is visited twice per offer; round 1 then works on per-offer and per-slot arrays, which the caches
// hold.
void slotsAndClosestInParallel(const std::vector<GroundOffer>& offers, GroundMapScratch& scratch, BevImage& map) {
  const auto cell_of_offer = [&](size_t i) { return offers[i].cell; };
  forEachPrefetchingCells(offers.size(), map.point_of_cell, cell_of_offer, [&](size_t i) {
    if (offers[i].cell >= 0) keepSmaller(asUnsigned(map.point_of_cell[offers[i].cell]), static_cast<uint32_t>(i), false);
  });
  std::vector<int32_t>& first_of_offer = scratch.first_of_offer;
  first_of_offer.resize(offers.size());
  forEachPrefetchingCells(offers.size(), map.point_of_cell, cell_of_offer, [&](size_t i) {
    first_of_offer[i] = offers[i].cell >= 0 ? map.point_of_cell[offers[i].cell] : -1;
  });
  std::vector<int32_t>& first_offers = scratch.first_offers;
  parallelSelect(offers.size(), [&](size_t i) { return first_of_offer[i] == static_cast<int32_t>(i); }, first_offers);
  const size_t slots = first_offers.size();
  sizeSlots(slots, scratch, map);
  std::vector<int32_t>& slot_of_offer = scratch.slot_of_offer;
  std::vector<ClosestKey>& closest = scratch.closest;
  slot_of_offer.resize(offers.size());
  forEachPrefetchingCells(
      slots, map.point_of_cell, [&](size_t slot) { return offers[first_offers[slot]].cell; },
      [&](size_t slot) {
        const int32_t first = first_offers[slot];
        const int32_t cell = offers[first].cell;
        map.cell[slot] = cell;
        map.point_of_cell[cell] = static_cast<int32_t>(slot);
        slot_of_offer[first] = static_cast<int32_t>(slot);
        closest[slot] = kNoClosestKey;
      });
  // An offer's slot is its cell's first offer's: those were all written above, and this loop writes only
  // the others'.
  parallelFor(offers.size(), [&](size_t i) {
    const int32_t first = first_of_offer[i];
    if (first < 0) return;
    if (first != static_cast<int32_t>(i)) slot_of_offer[i] = slot_of_offer[first];
    keepSmaller(closest[slot_of_offer[i]], closestWinsKey(offers[i].range, offers[i].source), false);
  });
}

}  // namespace

// A cell's or slot's winner is a minimum (keepSmaller()), which does not depend on the order the threads
// offer in, so the map is the same for any thread count and element by element the same as the CUDA
// backend's (bev_map.cu).
void fillGroundMap(float same_surface_distance, GroundMapScratch& scratch, BevImage& map) {
  const std::vector<GroundOffer>& offers = scratch.offers;
  const bool alone = runsAlone();
  takeOffGrid(map);
  // Round 1: the slots, and the closest offer per slot.
  if (alone) {
    slotsAndClosestAlone(offers, scratch, map);
  } else {
    slotsAndClosestInParallel(offers, scratch, map);
  }
  // Round 2: the oldest offer on that surface.
  const std::vector<int32_t>& slot_of_offer = scratch.slot_of_offer;
  const std::vector<ClosestKey>& closest = scratch.closest;
  std::vector<ClosestKey>& oldest = scratch.oldest;
  parallelFor(offers.size(), [&](size_t i) {
    const GroundOffer& offer = offers[i];
    if (offer.cell < 0) return;
    const int32_t slot = slot_of_offer[i];
    if (onClosestSurface(offer.range, closestWinsRange(closest[slot]), same_surface_distance)) {
      keepSmaller(oldest[slot], oldestWinsKey(offer.stamp, offer.source), alone);
    }
  });
  // The offer whose key its slot kept (sources are unique) writes the slot.
  parallelFor(offers.size(), [&](size_t i) {
    const GroundOffer& offer = offers[i];
    if (offer.cell < 0) return;
    const int32_t slot = slot_of_offer[i];
    if (oldest[slot] != oldestWinsKey(offer.stamp, offer.source)) return;
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
