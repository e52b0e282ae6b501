// "Closest wins per cell, in order of first arrival" on the GPU: the fill of a BEV map from a set of
// sources (scan pixels, a model and a scan fused, rendered map points), each cell keeping the oldest
// point on the surface closest to the sensor (the two rounds of model_update.hpp). bev_map.cu and
// map_render.cu define the sources; a Sources type provides counted() (itself, with any count that lives
// on the device read), count(), vertex(source), stamp(source) and offer(source, projection, range): the
// cell the source offers itself to (-1: none) and its range.
//
// Order of the compact points. The CPU backend's fill (fillGroundMap()) gives a cell the next slot when
// it is first offered a point, in source order, as one thread offering the sources in turn would. Here
// every source offers itself to its cell twice at once, with an atomicMin of its closest-wins key (the
// first round of which point stays) and of its source index (which source arrived first). A first
// arrival's slot is the number of first arrivals before it in source order, so both backends' maps agree
// element by element, in the same order.
//
// Three launches per map. Sources are taken in tiles of kThreads, tile t by a block of its own (a
// grid-stride loop over tiles, as the fusion's source count lives on the device):
//  1. offerClosest: the first round, and the target map's previous points taken off its grid;
//  2. offerOldestOnClosestSurface: the second round, each source's first-arrival flag and each tile's
//     count of first arrivals;
//  3. writeWinners: a tile's first slot is the sum of the counts of the tiles before it (summed again by
//     every block: a few hundred integers for a scan, a few thousand for a map's ground within the grid;
//     a block sums them in microseconds, cheaper than a launch), each first arrival's slot within the
//     tile a block scan of the flags; integer sums, exact in any order.
#pragma once

#include <cub/block/block_reduce.cuh>
#include <cub/block/block_scan.cuh>

#include "core/common/model_update.hpp"
#include "core/cuda/kernels.hpp"
#include "core/cuda/launch.cuh"

namespace elo::cuda::cell_compaction {

__device__ inline int tilesFor(int sources) { return (sources + kThreads - 1) / kThreads; }

// Takes the map's points off its grid (BevImage::clear()), leaving its count to the caller.
__device__ inline void takeOffGrid(const DeviceBev& map) {
  const int count = *map.count;
  for (int i = globalThread(); i < count; i += gridThreads()) map.point_of_cell[map.cells[i]] = -1;
}

// The first round, and the target map's grid emptied for writeWinners (nothing reads it before).
template <typename Sources>
__global__ void offerClosest(Sources offered, BevProjection projection, CellCompaction compaction, DeviceBev map) {
  takeOffGrid(map);  // its count is rewritten by writeWinners
  const Sources sources = offered.counted();
  const int count = sources.count();
  for (int source = globalThread(); source < count; source += gridThreads()) {
    float range = 0.0f;
    const int cell = sources.offer(source, projection, range);
    compaction.source_cells[source] = cell;
    if (cell < 0) continue;
    atomicMin(&compaction.cell_keys[cell], closestWinsKey(range, static_cast<uint32_t>(source)));
    atomicMin(&compaction.first_sources[cell], static_cast<uint32_t>(source));
  }
}

// The second round: a source on its cell's closest surface offers its age. Its range is computed as its
// first offer computed it. The first round is complete, so is each cell's first arrival.
template <typename Sources>
__global__ void offerOldestOnClosestSurface(Sources offered, float same_surface_distance, CellCompaction compaction) {
  const Sources sources = offered.counted();
  const int count = sources.count();
  const int tiles = tilesFor(count);
  for (int tile = blockIdx.x; tile < tiles; tile += gridDim.x) {
    const int source = tile * kThreads + static_cast<int>(threadIdx.x);
    const int cell = source < count ? compaction.source_cells[source] : -1;
    bool first = false;
    if (cell >= 0) {
      first = compaction.first_sources[cell] == static_cast<uint32_t>(source);
      const float range = norm(sources.vertex(static_cast<uint32_t>(source)));
      if (onClosestSurface(range, closestWinsRange(compaction.cell_keys[cell]), same_surface_distance)) {
        atomicMin(&compaction.surface_keys[cell],
                  oldestWinsKey(sources.stamp(static_cast<uint32_t>(source)), static_cast<uint32_t>(source)));
      }
    }
    if (source < count) compaction.first_flags[source] = first ? 1 : 0;
    const int tile_firsts = __syncthreads_count(first);
    if (threadIdx.x == 0) compaction.tile_firsts[tile] = tile_firsts;
  }
}

using TileReduce = cub::BlockReduce<int, kThreads>;
using TileScan = cub::BlockScan<int, kThreads>;

// The first arrivals in the tiles before `tile`, in every thread of the block.
__device__ inline int firstsBefore(const int* tile_firsts, int tile, TileReduce::TempStorage& storage, int& shared_sum) {
  int sum = 0;
  for (int i = static_cast<int>(threadIdx.x); i < tile; i += kThreads) sum += tile_firsts[i];
  sum = TileReduce(storage).Sum(sum);
  if (threadIdx.x == 0) shared_sum = sum;
  __syncthreads();
  const int before = shared_sum;
  __syncthreads();  // shared_sum and `storage` are free again
  return before;
}

// The first arrival in each cell writes the cell's winner into its slot and returns the cell's scratch to
// "none"; no other thread touches that cell here.
template <typename Sources>
__global__ void writeWinners(Sources offered, CellCompaction compaction, DeviceBev map) {
  __shared__ TileReduce::TempStorage reduce_storage;
  __shared__ TileScan::TempStorage scan_storage;
  __shared__ int shared_sum;
  const Sources sources = offered.counted();
  const int count = sources.count();
  const int tiles = tilesFor(count);
  if (tiles == 0 && globalThread() == 0) *map.count = 0;
  for (int tile = blockIdx.x; tile < tiles; tile += gridDim.x) {
    const int tile_slot = firstsBefore(compaction.tile_firsts, tile, reduce_storage, shared_sum);
    const int source = tile * kThreads + static_cast<int>(threadIdx.x);
    const int first = source < count ? compaction.first_flags[source] : 0;
    int slot_in_tile = 0;
    int tile_firsts = 0;
    TileScan(scan_storage).ExclusiveSum(first, slot_in_tile, tile_firsts);
    __syncthreads();  // scan_storage is free again for the next tile
    if (tile == tiles - 1 && threadIdx.x == 0) *map.count = tile_slot + tile_firsts;
    if (first == 0) continue;
    const int cell = compaction.source_cells[source];
    const uint32_t winner = oldestWinsSource(compaction.surface_keys[cell]);
    const int slot = tile_slot + slot_in_tile;
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
}

// Runs the three launches above with `blocks` blocks: enough for every tile where the source count is
// known on the host, a fixed grid where it lives on the device.
template <typename Sources>
void compact(const Sources& sources, int blocks, const BevProjection& projection, float same_surface_distance,
             const CellCompaction& compaction, const DeviceBev& map, cudaStream_t stream) {
  offerClosest<<<blocks, kThreads, 0, stream>>>(sources, projection, compaction, map);
  checkLaunch("offerClosest");
  offerOldestOnClosestSurface<<<blocks, kThreads, 0, stream>>>(sources, same_surface_distance, compaction);
  checkLaunch("offerOldestOnClosestSurface");
  writeWinners<<<blocks, kThreads, 0, stream>>>(sources, compaction, map);
  checkLaunch("writeWinners");
}

}  // namespace elo::cuda::cell_compaction
