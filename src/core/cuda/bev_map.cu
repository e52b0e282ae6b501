// Sec. III-C.2 and III-D on the GPU: BEV maps that keep in each cell the oldest point on the surface
// closest to the sensor (the two rounds of model_update.hpp), and the normals of the BEV model.
//
// Order of the compact points. The CPU backend offers sources one at a time (fillGroundMap()): a cell
// takes the next slot when it is first offered a point. Here every source offers itself to its cell
// twice at once, with an atomicMin of its closest-wins key (the first round of which point stays) and of
// its source index (which source arrived first). The first arrivals, prefix-summed in source order, give
// the slots, so both backends' maps agree element by element, in the same order.
#include "core/common/model_update.hpp"
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

// The points of the scan's ground map come from the pixels of the scan image.
struct PixelSources {
  const Float3* vertices;
  const float* stamps;

  __device__ Float3 vertex(uint32_t source) const { return vertices[source]; }
  __device__ float stamp(uint32_t source) const { return stamps[source]; }
};

// The points of a fused ground map: model points 0..model_points-1 moved into the scan's frame, then the
// scan's ground points.
struct FusionSources {
  DeviceBev model;
  int model_points;
  DeviceBev scan;
  Rigid3f scan_from_model;

  __device__ bool fromModel(uint32_t source) const { return source < static_cast<uint32_t>(model_points); }
  __device__ Float3 vertex(uint32_t source) const {
    return fromModel(source) ? scan_from_model.apply(model.vertices[source]) : scan.vertices[source - model_points];
  }
  __device__ float stamp(uint32_t source) const {
    return fromModel(source) ? model.stamps[source] : scan.stamps[source - model_points];
  }
};

// `source` offers a point at `range` to `cell` (-1: to none).
__device__ void offer(const CellCompaction& compaction, int source, int cell, float range) {
  compaction.source_cells[source] = cell;
  if (cell < 0) return;
  atomicMin(&compaction.cell_keys[cell], closestWinsKey(range, static_cast<uint32_t>(source)));
  atomicMin(&compaction.first_sources[cell], static_cast<uint32_t>(source));
}

__global__ void offerGroundPixels(DeviceScan scan, BevProjection projection, CellCompaction compaction) {
  const int pixel = globalThread();
  if (pixel >= scan.pixels()) return;
  int cell = -1;
  float range = 0.0f;
  int row = 0;
  int col = 0;
  if (scan.labels[pixel] == PixelLabel::ground && projection.cellOf(scan.vertices[pixel], row, col)) {
    cell = row * projection.cols + col;
    range = norm(scan.vertices[pixel]);
  }
  offer(compaction, pixel, cell, range);
}

// Sources beyond the model's points are scan slots; those past the scan's point count offer nothing.
__global__ void offerFusionSources(FusionSources sources, int source_count, BevProjection projection, ModelFusion fusion,
                                   CellCompaction compaction) {
  const int source = globalThread();
  if (source >= source_count) return;
  int cell = -1;
  float range = 0.0f;
  if (sources.fromModel(source)) {
    int row = 0;
    int col = 0;
    const Float3 moved = sources.scan_from_model.apply(sources.model.vertices[source]);
    if (isCurrent(fusion.now, sources.model.stamps[source], fusion.time_window) && projection.cellOf(moved, row, col)) {
      cell = row * projection.cols + col;
      range = norm(moved);
    }
  } else {
    const int point = source - sources.model_points;
    if (point < *sources.scan.count) {
      cell = sources.scan.cells[point];
      range = norm(sources.scan.vertices[point]);
    }
  }
  offer(compaction, source, cell, range);
}

// The second round: a source on its cell's closest surface offers its age. Its range is computed as its
// first offer computed it.
template <typename Sources>
__global__ void offerOldestOnClosestSurface(Sources sources, int source_count, float same_surface_distance,
                                            CellCompaction compaction) {
  const int source = globalThread();
  if (source >= source_count) return;
  const int cell = compaction.source_cells[source];
  if (cell < 0) return;
  const float range = norm(sources.vertex(static_cast<uint32_t>(source)));
  if (onClosestSurface(range, closestWinsRange(compaction.cell_keys[cell]), same_surface_distance)) {
    atomicMin(&compaction.surface_keys[cell], oldestWinsKey(sources.stamp(static_cast<uint32_t>(source)),
                                                           static_cast<uint32_t>(source)));
  }
}

__global__ void flagFirstArrivals(int source_count, CellCompaction compaction) {
  const int source = globalThread();
  if (source >= source_count) return;
  const int cell = compaction.source_cells[source];
  compaction.first_flags[source] = cell >= 0 && compaction.first_sources[cell] == static_cast<uint32_t>(source) ? 1 : 0;
}

// The first arrival in each cell writes the cell's winner into its slot and returns the cell's scratch to
// "none"; no other thread touches that cell here.
template <typename Sources>
__global__ void writeWinners(Sources sources, int source_count, CellCompaction compaction, DeviceBev map) {
  const int source = globalThread();
  if (source >= source_count) return;
  if (source == source_count - 1) *map.count = compaction.offsets[source] + compaction.first_flags[source];
  if (compaction.first_flags[source] == 0) return;
  const int cell = compaction.source_cells[source];
  const uint32_t winner = closestWinsSource(compaction.surface_keys[cell]);
  const int slot = compaction.offsets[source];
  const Float3 vertex = sources.vertex(winner);
  map.cells[slot] = cell;
  map.vertices[slot] = vertex;
  map.ranges[slot] = norm(vertex);
  map.stamps[slot] = sources.stamp(winner);
  map.point_of_cell[cell] = slot;
  compaction.cell_keys[cell] = kNoClosestKey;
  compaction.surface_keys[cell] = kNoClosestKey;
  compaction.first_sources[cell] = kNoSource;
}

// Empties the grid cells of the map's points (BevImage::clear()); the count is left to the caller.
__global__ void clearCells(DeviceBev map) {
  const int count = *map.count;
  for (int i = globalThread(); i < count; i += gridThreads()) map.point_of_cell[map.cells[i]] = -1;
}

__global__ void copyPoints(DeviceBev from, DeviceBev to) {
  const int count = *from.count;
  if (globalThread() == 0) *to.count = count;
  for (int i = globalThread(); i < count; i += gridThreads()) {
    to.cells[i] = from.cells[i];
    to.vertices[i] = from.vertices[i];
    to.ranges[i] = from.ranges[i];
    to.stamps[i] = from.stamps[i];
    to.point_of_cell[from.cells[i]] = i;
  }
}

__global__ void groundNormals(DeviceBev model, BevProjection projection, int wanted, int patch_radius,
                              Float3* normals) {
  const int count = *model.count;
  for (int point = globalThread(); point < count; point += gridThreads()) {
    normals[point] = groundNormal(model, projection, point, wanted, patch_radius);
  }
}

void clearCellsOf(const DeviceBev& map, cudaStream_t stream) {
  clearCells<<<kGridStrideBlocks, kThreads, 0, stream>>>(map);
  checkLaunch("clearCells");
}

// Runs the second round over the offers made, flags their first arrivals, sums them into slots and writes
// the winners into `map`.
template <typename Sources>
void compactWinners(const Sources& sources, int source_count, float same_surface_distance,
                    const CellCompaction& compaction, const DeviceBev& map, cudaStream_t stream) {
  offerOldestOnClosestSurface<<<blocksFor(source_count), kThreads, 0, stream>>>(sources, source_count,
                                                                                same_surface_distance, compaction);
  checkLaunch("offerOldestOnClosestSurface");
  flagFirstArrivals<<<blocksFor(source_count), kThreads, 0, stream>>>(source_count, compaction);
  checkLaunch("flagFirstArrivals");
  exclusiveSum(compaction.first_flags, compaction.offsets, source_count, compaction.scan_scratch,
               compaction.scan_scratch_bytes, stream);
  writeWinners<<<blocksFor(source_count), kThreads, 0, stream>>>(sources, source_count, compaction, map);
  checkLaunch("writeWinners");
}

}  // namespace

void buildGroundMap(const DeviceScan& scan, const BevProjection& projection, float same_surface_distance,
                    const DeviceBev& ground, const CellCompaction& compaction, cudaStream_t stream) {
  const int pixels = scan.pixels();
  clearCellsOf(ground, stream);
  offerGroundPixels<<<blocksFor(pixels), kThreads, 0, stream>>>(scan, projection, compaction);
  checkLaunch("offerGroundPixels");
  compactWinners(PixelSources{scan.vertices, scan.stamps}, pixels, same_surface_distance, compaction, ground, stream);
}

void fuseGroundModel(const DeviceBev& model, int model_points, const DeviceBev& scan_ground, int scan_slots,
                     const BevProjection& projection, const Rigid3f& scan_from_model, const ModelFusion& fusion,
                     const DeviceBev& fused, const CellCompaction& compaction, cudaStream_t stream) {
  const FusionSources sources{model, model_points, scan_ground, scan_from_model};
  const int source_count = model_points + scan_slots;
  clearCellsOf(fused, stream);
  offerFusionSources<<<blocksFor(source_count), kThreads, 0, stream>>>(sources, source_count, projection, fusion,
                                                                       compaction);
  checkLaunch("offerFusionSources");
  compactWinners(sources, source_count, fusion.same_surface_distance, compaction, fused, stream);
}

void copyGroundMap(const DeviceBev& from, const DeviceBev& to, cudaStream_t stream) {
  clearCellsOf(to, stream);
  copyPoints<<<kGridStrideBlocks, kThreads, 0, stream>>>(from, to);
  checkLaunch("copyPoints");
}

void clearGroundMap(const DeviceBev& map, cudaStream_t stream) {
  clearCellsOf(map, stream);
  check(cudaMemsetAsync(map.count, 0, sizeof(int), stream), "clearing a ground map's count");
}

void fitGroundNormals(const DeviceBev& model, const BevProjection& projection, int wanted, int patch_radius,
                      Float3* normals, cudaStream_t stream) {
  groundNormals<<<kGridStrideBlocks, kThreads, 0, stream>>>(model, projection, wanted, patch_radius, normals);
  checkLaunch("groundNormals");
}

}  // namespace elo::cuda
