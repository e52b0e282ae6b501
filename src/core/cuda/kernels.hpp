// The launches of each stage of the CUDA backend, declared for its host code (cuda_backend.cpp): device
// buffers in, all work queued on `stream`, nothing waited for. The per-element math is the shared code of
// src/core/common; the .cu files add the indexing, the atomics and the reductions.
#pragma once

#include <cuda_runtime_api.h>

#include <cstddef>
#include <cstdint>

#include "core/common/association.hpp"
#include "core/common/closest_wins_key.hpp"
#include "core/common/deskew.hpp"
#include "core/common/ground.hpp"
#include "core/common/map_render.hpp"
#include "core/common/model_update.hpp"
#include "core/common/normals.hpp"
#include "core/common/point_to_plane.hpp"
#include "core/cuda/device_views.hpp"

namespace elo::cuda {

constexpr uint32_t kNoSource = ~uint32_t{0};  // all bytes 0xff

// Scratch of "closest wins per cell, in order of first arrival" (bev_map.cu). Per BEV cell: the
// closest-wins key and the lowest source offered to it, all back to "none" (all bytes 0xff) after each
// use. Per source: its cell (-1: none) and whether it arrived first in that cell; per tile of sources
// (compactionTiles()), its count of first arrivals.
struct CellCompaction {
  ClosestKey* cell_keys;     // first round: the closest offer per cell
  ClosestKey* surface_keys;  // second round: the oldest offer on its closest surface (model_update.hpp)
  uint32_t* first_sources;
  int* source_cells;
  int* first_flags;
  int* tile_firsts;
};
// The tiles of `sources` sources, the size of CellCompaction::tile_firsts.
size_t compactionTiles(size_t sources);

// A list of the flagged items of a range, in order (the registration pixels).
struct FlaggedList {
  int* flags;
  int* offsets;
  int* items;
  int* count;
  void* scan_scratch;  // for exclusiveSum()
  size_t scan_scratch_bytes;
};

// compaction.cu: offsets[i] = flags[0] + ... + flags[i-1], and the scratch that needs.
size_t exclusiveSumScratchBytes(int max_items);
void exclusiveSum(const int* flags, int* offsets, int items, void* scratch, size_t scratch_bytes, cudaStream_t stream);

// projection.cu: the closest point of the uploaded cloud per pixel (Sec. III-B.1), each point deskewed
// first; `rings` is null when the cloud has no ring field, and `deskew.times` points to the uploaded
// times when the deskew needs them. Counts the occupied pixels into `*occupied`.
struct UploadedCloud {
  const Float3* points;
  const uint16_t* rings;
  int count;
};
void projectScan(const UploadedCloud& cloud, const SphericalProjection& projection,
                 const ElevationCorrection& correction, const SweepDeskew& deskew, const int* ring_rows,
                 int ring_count, float stamp, ClosestKey* pixel_keys, const DeviceScan& scan, int* occupied,
                 cudaStream_t stream);

// deskew.cu: every occupied pixel deskewed again, under `velocity` after `applied` (redeskewPixel()).
void deskewScan(const DeviceScan& scan, const SweepVelocity& applied, const SweepVelocity& velocity,
                cudaStream_t stream);
// deskew.cu: every occupied pixel of a scan turned by a gyro's rotation (SweepRotation) deskewed again,
// under `velocity` after `applied`: moved by the change of translation (turnedPixelMoved()); the normals
// stay.
void deskewTurnedScan(const DeviceScan& scan, const SweepVelocity& applied, const SweepVelocity& velocity,
                      cudaStream_t stream);

// ground_segmentation.cu (Sec. III-C.1).
void segmentGround(const DeviceScan& scan, const GroundBand& band, cudaStream_t stream);
void labelAllNonground(const DeviceScan& scan, cudaStream_t stream);

// normal_estimation.cu: the normals of the non-ground pixels (Sec. III-B.3-4), and the list of the
// non-ground pixels with a normal, in pixel order.
void estimateNormals(const DeviceScan& scan, const NormalParams& params, const FlaggedList& registration_pixels,
                     cudaStream_t stream);

// bev_map.cu: BEV maps (Sec. III-C.2, III-D). Each cell keeps the oldest point on its closest surface
// (model_update.hpp), the points in the order the CPU backend inserts them (see bev_map.cu). The scan's
// map takes the ground pixels that join it (joinsGroundMap(), `band`).
void buildGroundMap(const DeviceScan& scan, const GroundBand& band, const BevProjection& projection,
                    float same_surface_distance, const DeviceBev& ground, const CellCompaction& compaction,
                    cudaStream_t stream);
// The point counts of `model` and `scan_ground` are read on the device: nothing waits for them.
void fuseGroundModel(const DeviceBev& model, const DeviceBev& scan_ground, const BevProjection& projection,
                     const Rigid3f& scan_from_model, const ModelFusion& fusion, const DeviceBev& fused,
                     const CellCompaction& compaction, cudaStream_t stream);
void copyGroundMap(const DeviceBev& from, const DeviceBev& to, cudaStream_t stream);
void clearGroundMap(const DeviceBev& map, cudaStream_t stream);

// model_update.cu: the non-ground model (Sec. III-D).
// `closest_keys` and `surface_keys`, one per pixel, are scratch for the two rounds (model_update.hpp):
// "none" (all bytes 0xff) before, and again after.
void fuseSphericalModel(const DeviceModelImage& model, const DeviceScan& scan, const SphericalProjection& projection,
                        const Rigid3f& scan_from_model, const ModelFusion& fusion, ClosestKey* closest_keys,
                        ClosestKey* surface_keys, const DeviceModelImage& fused, cudaStream_t stream);
void copyScanToModel(const DeviceScan& scan, const DeviceModelImage& model, cudaStream_t stream);

// map_render.cu: localization's map model (common/map_render.hpp), as the CPU backend's renderMapModel()
// draws it. The part of the map a render needs lives on the device (MapResidency); a render reads the
// points `indices` lists, their places there.
struct DeviceMap {
  const Float3* points;
  const Float3* normals;
};
// One render's sources and their scratch: each listed point and its normal in the sensor's frame.
struct MapRenderSources {
  const int32_t* indices;
  int count;
  Float3* vertices;
  Float3* normals;
};
// The non-ground points with a normal go into `image`, closest wins per pixel over the discs they cover
// (`closest_keys`: one per pixel, "none" before and again after); the ground points into `ground` by the
// cell compaction, whose per-source arrays must hold `sources.count`.
void renderMapModel(const DeviceMap& map, const MapRenderSources& sources, const Rigid3f& sensor_from_map,
                    const SphericalProjection& spherical, const BevProjection& bev, const MapRendering& rendering,
                    ClosestKey* closest_keys, const DeviceModelImage& image, const DeviceBev& ground,
                    const CellCompaction& compaction, cudaStream_t stream);

// correspondences.cu: the Gauss-Newton sums of both cost terms (Sec. III-A), packed as
// point_to_plane.hpp lays them out, in one launch.
struct DeviceTermSums {
  double values[kTermValues];
  int candidates;
  int inliers;
};
constexpr int kTerms = 2;  // 0: non-ground (E_S), 1: ground (E_G)
// Blocks per term. Fixed, so that every GPU sums in the same order: results are reproducible run to run
// and across GPUs. Both terms' blocks (2 x 128 of kThreads, about 120 registers a thread: two blocks an
// SM) make one wave on a GPU of 128 SMs or more (an H100 has 132); a smaller GPU runs more waves.
constexpr int kReductionBlocks = 128;
// Rows of a block's partial sums: the packed sums, then the candidate and inlier counts.
constexpr int kPartialRows = kTermValues + 2;

// The normals of the model's ground points fitted so far (one slot per point): slot p holds point p's
// normal when epochs[p] equals `epoch`, which changes with every model update.
struct GroundNormalCache {
  Float3* normals;
  unsigned* epochs;
  unsigned epoch;
};

struct LinearizeInputs {
  bool nonground;  // which terms to sum, at least one; a term left out sums to zero
  bool ground;
  DeviceScan scan;
  const int* registration_pixels;
  const int* registration_count;
  DeviceModelImage model;
  SphericalProjection spherical;
  DeviceBev scan_ground;
  DeviceBev model_ground;
  BevProjection bev;
  GroundNormalCache ground_normals;
  int normal_neighbours;  // model points per ground normal (bev.normal_neighbours)
  int patch_radius;
  CorrespondenceGates gates;
  Rigid3f motion;
  double kernel_scale;
  float near_weight_range;  // registration.near_weight_range (nearWeight())
};
// The scratch of linearize(): every block's partial sums, term by term and row by row
// (kTerms * kPartialRows * kReductionBlocks), and the count of the blocks done, which must be 0 before
// the first launch and is 0 again after each.
struct LinearizeScratch {
  double* partials;
  unsigned* finished_blocks;
};
// `results`: the kTerms totals, written by the launch's last block. Pinned host memory (addressable by
// the device under unified addressing), so that the host reads them once the stream has got there.
void linearize(const LinearizeInputs& inputs, const LinearizeScratch& scratch, DeviceTermSums* results,
               cudaStream_t stream);

}  // namespace elo::cuda
