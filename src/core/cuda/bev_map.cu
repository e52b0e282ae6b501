// Sec. III-C.2 and III-D on the GPU: the scan's BEV map and the fused ground model, filled by the cell
// compaction of bev_compaction.cuh, which keeps in each cell the oldest point on the surface closest to
// the sensor, the points in the order the CPU backend inserts them.
#include "core/common/association.hpp"
#include "core/common/ground.hpp"
#include "core/common/model_update.hpp"
#include "core/cuda/bev_compaction.cuh"
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda {

namespace {

// The points of the scan's ground map come from the ground pixels of the scan image that join it.
struct PixelSources {
  DeviceScan scan;
  GroundBand band;

  __device__ PixelSources counted() const { return *this; }
  __device__ int count() const { return scan.pixels(); }
  __device__ Float3 vertex(uint32_t source) const { return scan.vertices[source]; }
  __device__ float stamp(uint32_t source) const { return scan.stamps[source]; }
  // The cell `source` offers itself to (-1: none) and its range.
  __device__ int offer(int source, const BevProjection& projection, float& range) const {
    int row = 0;
    int col = 0;
    if (!joinsGroundMap(scan.labels[source], scan.vertices[source], band) ||
        !projection.cellOf(scan.vertices[source], row, col)) {
      return -1;
    }
    range = norm(scan.vertices[source]);
    return row * projection.cols + col;
  }
};

// The points of a fused ground map: the model's points moved into the scan's frame, then the scan's
// ground points. Both counts are read on the device (counted()).
struct FusionSources {
  DeviceBev model;
  DeviceBev scan;
  Rigid3f scan_from_model;
  ModelFusion fusion;
  int model_points;
  int scan_points;

  __device__ FusionSources counted() const {
    FusionSources sources = *this;
    sources.model_points = *model.count;
    sources.scan_points = *scan.count;
    return sources;
  }
  __device__ int count() const { return model_points + scan_points; }
  __device__ bool fromModel(uint32_t source) const { return source < static_cast<uint32_t>(model_points); }
  __device__ Float3 vertex(uint32_t source) const {
    return fromModel(source) ? scan_from_model.apply(model.vertices[source]) : scan.vertices[source - model_points];
  }
  __device__ float stamp(uint32_t source) const {
    return fromModel(source) ? model.stamps[source] : scan.stamps[source - model_points];
  }
  // Model points that expired or left the grid offer themselves to no cell.
  __device__ int offer(int source, const BevProjection& projection, float& range) const {
    if (!fromModel(source)) {
      const int point = source - model_points;
      range = norm(scan.vertices[point]);
      return scan.cells[point];
    }
    int row = 0;
    int col = 0;
    const Float3 moved = scan_from_model.apply(model.vertices[source]);
    if (!isCurrent(fusion.now, model.stamps[source], fusion.time_window) || !projection.cellOf(moved, row, col)) {
      return -1;
    }
    range = norm(moved);
    return row * projection.cols + col;
  }
};

__global__ void clearCells(DeviceBev map) { cell_compaction::takeOffGrid(map); }

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

}  // namespace

size_t compactionTiles(size_t sources) { return (sources + kThreads - 1) / kThreads; }

void buildGroundMap(const DeviceScan& scan, const GroundBand& band, const BevProjection& projection,
                    float same_surface_distance, const DeviceBev& ground, const CellCompaction& compaction,
                    cudaStream_t stream) {
  cell_compaction::compact(PixelSources{scan, band}, blocksFor(scan.pixels()), projection, same_surface_distance,
                           compaction, ground, stream);
}

void fuseGroundModel(const DeviceBev& model, const DeviceBev& scan_ground, const BevProjection& projection,
                     const Rigid3f& scan_from_model, const ModelFusion& fusion, const DeviceBev& fused,
                     const CellCompaction& compaction, cudaStream_t stream) {
  const FusionSources sources{model, scan_ground, scan_from_model, fusion, 0, 0};
  cell_compaction::compact(sources, kWideGridBlocks, projection, fusion.same_surface_distance, compaction, fused,
                           stream);
}

void copyGroundMap(const DeviceBev& from, const DeviceBev& to, cudaStream_t stream) {
  clearCells<<<kGridStrideBlocks, kThreads, 0, stream>>>(to);
  checkLaunch("clearCells");
  copyPoints<<<kGridStrideBlocks, kThreads, 0, stream>>>(from, to);
  checkLaunch("copyPoints");
}

void clearGroundMap(const DeviceBev& map, cudaStream_t stream) {
  clearCells<<<kGridStrideBlocks, kThreads, 0, stream>>>(map);
  checkLaunch("clearCells");
  check(cudaMemsetAsync(map.count, 0, sizeof(int), stream), "clearing a ground map's count");
}

}  // namespace elo::cuda
