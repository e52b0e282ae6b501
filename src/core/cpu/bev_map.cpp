// Sec. III-C.2: the bird's-eye-view map of ground points, and the normals of the BEV model fitted to
// the model points nearest an associated cell (groundNormal() of association.hpp, shared with the CUDA
// backend).
#include <algorithm>

#include "core/common/association.hpp"
#include "core/common/eigen_interop.hpp"
#include "core/common/ground.hpp"
#include "core/cpu/image_views.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

std::vector<int32_t> groundPixels(const ScanImage& scan, const GroundBand& band) {
  std::vector<int32_t> pixels;
  const auto joins = [&](size_t pixel) {
    return joinsGroundMap(scan.label[pixel], toFloat3(scan.image.vertex[pixel]), band);
  };
  parallelSelect(scan.label.size(), joins, pixels);
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

// Offers are grouped by bands of 2^kBandShift consecutive grid cells (about 3.4 rows of the default
// grid): a band's cells are filled by one thread, so no two threads ever offer to one cell. Bands this
// narrow split a map's offers into enough groups for any thread count; a shift finds an offer's band
// without a division.
constexpr int kBandShift = 13;

// Copies the offers, grouped by band, into scratch.banded (band b's from band_start[b] to band_start[b + 1],
// each band's in the offers' order), leaving out those offered to no cell. A counting sort over fixed blocks of offers: each block counts its offers per band, the counts
// place every (band, block) run one after another, and each block writes its own runs, so the result is
// the same whatever the thread count.
void groupByBand(const std::vector<GroundOffer>& offers, size_t bands, GroundMapScratch& scratch) {
  const size_t blocks = (offers.size() + kFixedBlock - 1) / kFixedBlock;
  const auto band_of = [](int32_t cell) { return static_cast<size_t>(cell) >> kBandShift; };
  std::vector<int32_t>& place = scratch.band_place;  // [block * bands + band]: a count, then where the run starts
  place.resize(blocks * bands);
  // The count pass also marks every offer "not a first offer" for fillBand().
  scratch.first_position.resize(offers.size());
  parallelFor(blocks, [&](size_t block) {
    std::fill(place.begin() + static_cast<std::ptrdiff_t>(block * bands),
              place.begin() + static_cast<std::ptrdiff_t>((block + 1) * bands), 0);
    for (size_t i = block * kFixedBlock; i < std::min(offers.size(), (block + 1) * kFixedBlock); ++i) {
      scratch.first_position[i] = -1;
      if (offers[i].cell >= 0) ++place[block * bands + band_of(offers[i].cell)];
    }
  });
  std::vector<int32_t>& band_start = scratch.band_start;
  band_start.assign(bands + 1, 0);
  parallelFor(bands, [&](size_t band) {
    for (size_t block = 0; block < blocks; ++block) band_start[band + 1] += place[block * bands + band];
  });
  for (size_t band = 0; band < bands; ++band) band_start[band + 1] += band_start[band];
  parallelFor(bands, [&](size_t band) {
    int32_t at = band_start[band];
    for (size_t block = 0; block < blocks; ++block) {
      const int32_t count = place[block * bands + band];
      place[block * bands + band] = at;
      at += count;
    }
  });
  const size_t grouped = static_cast<size_t>(band_start[bands]);
  scratch.banded.resize(grouped);
  parallelFor(blocks, [&](size_t block) {
    for (size_t i = block * kFixedBlock; i < std::min(offers.size(), (block + 1) * kFixedBlock); ++i) {
      const GroundOffer& offer = offers[i];
      if (offer.cell < 0) continue;
      scratch.banded[place[block * bands + band_of(offer.cell)]++] = {offer.cell, offer.range, offer.stamp,
                                                                      offer.source, static_cast<int32_t>(i)};
    }
  });
}

// Both rounds for the cells of one band: its grouped offers [begin, end), in their order. A cell's state
// lives at its first offer's position: the grid holds that position meanwhile, `closest` and `oldest` the
// rounds' keys there, `winner` the index of the offer with the oldest key.
void fillBand(size_t begin, size_t end, float same_surface_distance, GroundMapScratch& scratch, BevImage& map) {
  const std::vector<BandedOffer>& banded = scratch.banded;
  prefetchingCells(
      begin, end, map.point_of_cell, [&](size_t at) { return banded[at].cell; },
      [&](size_t at) {
        const BandedOffer& offer = banded[at];
        int32_t& first = map.point_of_cell[offer.cell];
        const ClosestKey key = closestWinsKey(offer.range, offer.source);
        if (first < 0) {
          first = static_cast<int32_t>(at);
          scratch.closest[at] = key;
          scratch.oldest[at] = kNoClosestKey;
          scratch.first_position[offer.index] = first;
        } else if (key < scratch.closest[first]) {
          scratch.closest[first] = key;
        }
        scratch.first_of[at] = first;
      });
  for (size_t at = begin; at < end; ++at) {
    const BandedOffer& offer = banded[at];
    const int32_t first = scratch.first_of[at];
    if (!onClosestSurface(offer.range, closestWinsRange(scratch.closest[first]), same_surface_distance)) continue;
    const ClosestKey key = oldestWinsKey(offer.stamp, offer.source);
    if (key < scratch.oldest[first]) {
      scratch.oldest[first] = key;
      scratch.winner[first] = offer.index;
    }
  }
}

// The map on one thread, taking every offer in turn; a cell takes the next slot at its first offer. Here
// `first_of` holds each offer's slot, `oldest` and `winner` are per slot, and the map's ranges hold round
// 1's closest range.
void fillInTurn(float same_surface_distance, GroundMapScratch& scratch, BevImage& map) {
  const std::vector<GroundOffer>& offers = scratch.offers;
  std::vector<int32_t>& slot_of_offer = scratch.first_of;
  slot_of_offer.resize(offers.size());
  prefetchingCells(
      0, offers.size(), map.point_of_cell, [&](size_t i) { return offers[i].cell; },
      [&](size_t i) {
        const GroundOffer& offer = offers[i];
        if (offer.cell < 0) return;
        int32_t& slot = map.point_of_cell[offer.cell];
        if (slot < 0) {
          slot = static_cast<int32_t>(map.cell.size());
          map.cell.push_back(offer.cell);
          map.range.push_back(offer.range);
        } else if (offer.range < map.range[slot]) {
          map.range[slot] = offer.range;
        }
        slot_of_offer[i] = slot;
      });
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
  for (size_t slot = 0; slot < slots; ++slot) {
    const GroundOffer& kept = offers[winner[slot]];
    map.vertex[slot] = kept.vertex;
    map.range[slot] = kept.range;
    map.stamp[slot] = kept.stamp;
  }
}

// The map across threads: the offers grouped by band, each band's cells filled by one thread in the
// offers' order, which is what fillInTurn() does for them; the slots then follow the first offers in
// their order. No atomics are needed, and the map is fillInTurn()'s.
void fillByBands(float same_surface_distance, GroundMapScratch& scratch, BevImage& map) {
  const std::vector<GroundOffer>& offers = scratch.offers;
  const size_t bands = (map.cellCount() >> kBandShift) + 1;
  groupByBand(offers, bands, scratch);
  const size_t grouped = scratch.banded.size();
  scratch.first_of.resize(grouped);
  scratch.closest.resize(grouped);
  scratch.oldest.resize(grouped);
  scratch.winner.resize(grouped);
  parallelFor(bands, [&](size_t band) {
    fillBand(scratch.band_start[band], scratch.band_start[band + 1], same_surface_distance, scratch, map);
  });
  std::vector<int32_t>& first_offers = scratch.first_offers;
  parallelSelect(offers.size(), [&](size_t i) { return scratch.first_position[i] >= 0; }, first_offers);
  const size_t slots = first_offers.size();
  map.cell.resize(slots);
  map.vertex.resize(slots);
  map.range.resize(slots);
  map.stamp.resize(slots);
  forEachPrefetchingCells(
      slots, map.point_of_cell, [&](size_t slot) { return offers[first_offers[slot]].cell; },
      [&](size_t slot) {
        const GroundOffer& kept = offers[scratch.winner[scratch.first_position[first_offers[slot]]]];
        const int32_t cell = offers[first_offers[slot]].cell;
        map.cell[slot] = cell;
        map.point_of_cell[cell] = static_cast<int32_t>(slot);
        map.vertex[slot] = kept.vertex;
        map.range[slot] = kept.range;
        map.stamp[slot] = kept.stamp;
      });
}

}  // namespace

// Grouping the offers costs about as much as filling the map, so it pays only where more than two threads
// share it. Both ways give the same map, element by element the same as the CUDA backend's (bev_map.cu),
// whatever the thread count.
void fillGroundMap(float same_surface_distance, GroundMapScratch& scratch, BevImage& map) {
  takeOffGrid(map);
  if (tbb::this_task_arena::max_concurrency() > 2) {
    fillByBands(same_surface_distance, scratch, map);
  } else {
    fillInTurn(same_surface_distance, scratch, map);
  }
}

void GroundNormalCache::reset(size_t points) {
  if (points > capacity_) {
    capacity_ = points + points / 2;
    normals_.resize(capacity_);
    states_ = std::make_unique<std::atomic<uint8_t>[]>(capacity_);
  }
  parallelFor(points, [&](size_t i) { states_[i].store(unknown, std::memory_order_relaxed); });
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
