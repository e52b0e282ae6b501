// The per-frame stages of the CPU backend as free functions, one file each, so that each can be tested
// on its own. They parallelise with TBB inside whatever task arena calls them.
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <memory>

#include "core/common/deskew.hpp"
#include "core/common/eigen_interop.hpp"
#include "core/common/ground.hpp"
#include "core/common/map_render.hpp"
#include "core/common/model_update.hpp"
#include "core/common/normals.hpp"
#include "core/common/scan_projection.hpp"
#include "core/cpu/closest_wins.hpp"
#include "elo/pipeline/backend.hpp"
#include "elo/sensor/sensor_model.hpp"

namespace elo::cpu {

// projection.cpp: the closest point of the cloud per pixel, every point deskewed by `deskew` first;
// `ring_rows` maps a driver's ring index to its row (empty: rows from the elevation). `winners` must be
// empty, as resize() leaves it, and is left empty. `placed` is scratch: each cloud point as placed, where
// the points are corrected or deskewed (otherwise the winners are read from the cloud itself). Returns
// the number of occupied pixels.
size_t projectCloud(const PointCloud& cloud, const SensorConfig& sensor, const SphericalProjection& projection,
                    const std::vector<int>& ring_rows, const SweepDeskew& deskew, float stamp, ClosestWins& winners,
                    std::vector<ScanPoint>& placed, ScanImage& scan);

// deskew.cpp: every occupied pixel deskewed again, under `velocity` after `applied` (redeskewPixel()).
void deskewScan(const SweepVelocity& applied, const SweepVelocity& velocity, ScanImage& scan);
// deskew.cpp: every occupied pixel of a scan turned by a gyro's rotation (SweepRotation) deskewed again,
// under `velocity` after `applied`: moved by the change of translation (turnedPixelMoved()); the normals
// stay.
void deskewTurnedScan(const SweepVelocity& applied, const SweepVelocity& velocity, ScanImage& scan);

// ground_segmentation.cpp: labels occupied pixels ground or non-ground, column by column.
void segmentGround(const GroundBand& band, ScanImage& scan);
// Every occupied pixel non-ground (the "spherical, all points" variant of Table II).
void labelAllNonground(ScanImage& scan);

// normal_estimation.cpp: normals of the non-ground pixels by the configured method.
using elo::WindowSize;
// The range-adaptive window of Eq. 12 for a point at `range`.
WindowSize rangeAdaptiveWindow(const NormalConfig& config, const SphericalProjection& projection, float range);
// The non-ground image as separate coordinate planes and a 0/1 mask, so that the window loops of the
// normal estimator run over plain float arrays and vectorise. Each row is padded on both sides with the
// columns of its other end (azimuth is circular), so every window row is one contiguous segment of
// `span` pixels (a multiple of 16) centred on the pixel. Kept by the backend to reuse its memory.
struct NormalScratch {
  int span = 0;    // segment length: the widest window rounded up to 16 lanes
  int stride = 0;  // cols + span
  std::vector<float> x, y, z;
  std::vector<float> usable;  // 1 for a non-ground pixel, else 0
  std::vector<float> window_mask;  // per half-width h: span lanes, 1 where |lane - span/2| <= h

  void fill(const ScanImage& scan, int max_window_width);
  size_t segmentStart(int row, int col) const {  // first element of the segment centred on (row, col)
    return static_cast<size_t>(row) * stride + col;
  }
};
void estimateNormals(const NormalConfig& config, const SphericalProjection& projection, NormalScratch& scratch,
                     ScanImage& scan);

// A point offered to a cell of a ground map by source `source` (the numbering the CUDA backend uses);
// cell -1 offers nothing.
struct GroundOffer {
  int32_t cell = -1;
  Vec3f vertex;
  float range = 0.0f;  // distance to the sensor, as BevImage computes it
  float stamp = 0.0f;
  uint32_t source = 0;

  GroundOffer() = default;
  GroundOffer(int32_t to_cell, const Vec3f& point, float observed_at, uint32_t from_source)
      : cell(to_cell), vertex(point), range(norm(toFloat3(point))), stamp(observed_at), source(from_source) {}
};

// An offer as the fill's bands take it (fillGroundMap()): what its two rounds read, and its index among
// the offers.
struct BandedOffer {
  int32_t cell;
  float range;
  float stamp;
  uint32_t source;
  int32_t index;
};

// The offers a ground map is filled with (fillGroundMap()) and the fill's own arrays, kept by the
// backend so that no frame allocates them again (each fresh allocation costs page faults and zeroing).
struct GroundMapScratch {
  std::vector<GroundOffer> offers;  // in the order of their sources
  // The offers grouped by bands of grid cells (fillGroundMap() from three threads on), and the counting
  // sort's own arrays.
  std::vector<BandedOffer> banded;
  std::vector<int32_t> band_start;
  std::vector<int32_t> band_place;
  // Per grouped offer: the position of its cell's first offer. There, per cell: the closest offer's key
  // (round 1), the oldest key on that surface (round 2) and that offer's index. (Taking the offers in
  // turn, first_of holds each offer's slot, and oldest and winner are per slot.)
  std::vector<int32_t> first_of;
  std::vector<ClosestKey> closest;
  std::vector<ClosestKey> oldest;
  std::vector<int32_t> winner;
  std::vector<int32_t> first_position;  // per offer: its position if it is its cell's first, else -1
  std::vector<int32_t> first_offers;    // per slot: the first offer to its cell
};

// bev_map.cpp: the ground pixels that join the scan's ground map (joinsGroundMap()), in increasing order.
std::vector<int32_t> groundPixels(const ScanImage& scan, const GroundBand& band);
// The BEV map of the ground pixels `ground_pixels` (groundPixels()): per cell, the first pixel on the
// closest surface (fillGroundMap below).
void buildGroundMap(const ScanImage& scan, const std::vector<int32_t>& ground_pixels, const BevProjection& projection,
                    float same_surface_distance, GroundMapScratch& scratch, BevImage& ground);
// Fills `map` with `scratch.offers` by the two rounds of model_update.hpp: each cell keeps the oldest offer
// on its closest surface. Slots follow the first offer to each cell. Offers to cell -1 are passed over.
void fillGroundMap(float same_surface_distance, GroundMapScratch& scratch, BevImage& map);

// Normals of the BEV model, fitted on demand to the model points nearest each associated cell
// (Sec. III-C.2, groundNormal() of association.hpp) and kept until the model changes. Safe to query from
// many threads: a cell is fitted from the model alone, so whichever thread fits it first stores the same
// value any other would.
class GroundNormalCache {
 public:
  // Forgets every normal, across the threads of the current arena; call whenever the model changes, with
  // its new point count.
  void reset(size_t points);
  // Starts loading what normal() will read for `point`.
  void prefetch(int32_t point) const {
    __builtin_prefetch(&states_[point]);
    __builtin_prefetch(&normals_[point]);
  }
  // The normal of model point `point` (zero when its neighbours give no plane).
  Vec3f normal(const BevImage& model, const BevProjection& projection, const BevConfig& config, int32_t point);

 private:
  enum State : uint8_t { unknown = 0, fitting = 1, fitted = 2 };
  size_t capacity_ = 0;
  std::vector<Vec3f> normals_;
  std::unique_ptr<std::atomic<uint8_t>[]> states_;
};

// correspondences.cpp: the Gauss-Newton sums of each cost term for the scan moved by `model_from_scan`.
// The non-ground term runs over `pixels`: the non-ground pixels with a normal, listed once per scan.
std::vector<int32_t> registrationPixels(const ScanImage& scan);
TermSums nongroundSums(const ScanImage& scan, const std::vector<int32_t>& pixels, const SphericalImage& model,
                       const SphericalProjection& projection, const Eigen::Isometry3d& model_from_scan,
                       double kernel_scale, const RegistrationConfig& config);
TermSums groundSums(const BevImage& scan_ground, const BevImage& model, const BevProjection& projection,
                    GroundNormalCache& normals, const Eigen::Isometry3d& model_from_scan, double kernel_scale,
                    const RegistrationConfig& registration, const BevConfig& bev);

// model_update.cpp: moves the model into the scan's frame and fuses the scan into it: the closest surface
// wins a pixel and its oldest point stays (model_update.hpp); model points older than the time window go.
// Results go to `fused`.
//
// The spherical update's scratch, kept by the backend to reuse its memory: each pixel's winner of each
// round among the model's offers (empty between updates, as resize() leaves them), where each model pixel
// lands once moved into the scan's frame, and the key each scan pixel offers to itself. A scan pixel
// offers only to its own pixel, so its offer needs no atomic: the pass that reads the winners adds it.
struct SphericalFusionScratch {
  struct Moved {
    int32_t pixel;  // the pixel a model pixel lands on; -1 when it is not offered
    float range;    // its range there
  };
  ClosestWins closest;                // round 1: the closest model offer
  ClosestWins oldest;                 // round 2: the oldest model offer on the closest surface
  std::vector<Moved> moved;           // per model pixel
  std::vector<ClosestKey> scan_key;   // per scan pixel: its round-1 key, kNoClosestKey when it does not join

  void resize(size_t pixels);
};
void fuseSphericalModel(const SphericalImage& model, const ScanImage& scan, const SphericalProjection& projection,
                        const Eigen::Isometry3d& model_from_scan, const ModelFusion& fusion,
                        SphericalFusionScratch& scratch, SphericalImage& fused);
void fuseGroundModel(const BevImage& model, const BevImage& scan_ground, const BevProjection& projection,
                     const Eigen::Isometry3d& model_from_scan, const ModelFusion& fusion, GroundMapScratch& scratch,
                     BevImage& fused);
// Frame-to-frame: the model becomes the scan's non-ground features and ground map.
void copyScanToModel(const ScanImage& scan, const BevImage& scan_ground, Model& model);

// map_render.cpp: a saved map's points rendered into a model, as seen from a sensor pose (localization).
// The scratch: each pixel's closest offer, and each listed point moved into the sensor's frame.
struct MapRenderScratch {
  ClosestWins closest;
  std::vector<Float3> vertex;
  std::vector<Float3> normal;
  GroundMapScratch ground;
};
// Renders `points` of `map` (which has normals) moved by `sensor_from_map` into `model`: the non-ground
// points with a normal into its range image, closest wins per pixel, each covering the pixels its disc
// spans (normals turned towards the sensor); the ground points into its BEV map.
void renderMapModel(const MapCloud& map, const std::vector<int32_t>& points, const Rigid3f& sensor_from_map,
                    const SphericalProjection& spherical, const BevProjection& bev, const MapRendering& rendering,
                    MapRenderScratch& scratch, Model& model);

}  // namespace elo::cpu
