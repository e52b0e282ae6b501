// The drive's map (docs/map.md): every processed scan's deskewed points, placed by the scan's registered
// pose, accumulated into voxels in the odometry frame, one point per voxel: the centroid of its points,
// their mean intensity and, where the pipeline estimated normals, their mean normal. Memory grows with
// the area driven, not with time: a voxel seen again only adds to its sums. Apart from the odometry:
// it reads a scan's host view (Backend::scan()) after the scan has been processed.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "elo/config.hpp"
#include "elo/map/map_cloud.hpp"
#include "elo/types.hpp"

namespace elo {

// What one scan gives the map: its occupied pixels, deskewed, in the frame `pose` places in the map's
// frame (Odometry::modelPose() for the odometry frame). Normals are zero where the pipeline has none
// (ground pixels, and non-ground pixels its curvature gate rejected), and point towards the sensor.
struct MapScan {
  std::vector<Vec3f> points;
  std::vector<Vec3f> normals;
  std::vector<float> intensity;
  std::vector<uint8_t> ground;  // 1 where the pipeline labelled the pixel ground
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  double stamp = 0.0;  // the scan's stamp (s)
};

// Copies the scan's occupied pixels out of `scan` (Backend::scan() after Odometry::process()), with the
// intensity of each pixel's point in `cloud` (0 when the cloud has none). Close to the sensor, where
// neighbouring columns lie much less than `voxel_size` apart, it takes only as many columns as still
// give every voxel a point: their points would only add to the same centroids.
MapScan mapScanOf(const ScanImage& scan, const PointCloud& cloud, const Eigen::Isometry3d& pose, double stamp,
                  double voxel_size);

// Which registered scans go into the map: every MapConfig::scan_stride-th, the first after a clear()
// included.
class MapScanSelection {
 public:
  explicit MapScanSelection(int stride) : stride_(static_cast<uint64_t>(std::max(stride, 1))) {}
  // Call once for each registered scan: true when the map takes it.
  bool takes() { return registered_++ % stride_ == 0; }
  void clear() { registered_ = 0; }

 private:
  uint64_t stride_;
  uint64_t registered_ = 0;
};

class DriveMap {
 public:
  // Throws ConfigError for an unusable map config (validate()).
  explicit DriveMap(const MapConfig& config);

  void add(const MapScan& scan);
  void clear();

  // The voxels that pass the moving-object filter (MapConfig::min_observations), one point each, each
  // with its intensity and normal (zero where none is known); with `stride` > 1 only every stride-th of
  // them (a thinned map for display).
  MapCloud points(size_t stride = 1) const;

  size_t voxelCount() const { return voxels_; }
  size_t scanCount() const { return scans_; }
  // Points left out: not finite, more than a kilometre from the sensor, or beyond the map's extent
  // (about +-1,600 km at 0.2 m voxels).
  size_t pointsOutside() const { return outside_; }
  // The bytes the voxels and their index hold, capacity included.
  size_t memoryBytes() const;
  const MapConfig& config() const { return config_; }

 private:
  static constexpr int kBlockShift = 3;
  static constexpr int kBlockSide = 1 << kBlockShift;  // voxels along a block's side
  static constexpr int kBlockVoxels = kBlockSide * kBlockSide * kBlockSide;

  // Sums over the points that fell into one voxel. Positions are kept relative to the block's corner,
  // so that floats hold them to well under a millimetre anywhere in the map.
  struct Voxel {
    Vec3f position_sum = Vec3f::Zero();
    Vec3f normal_sum = Vec3f::Zero();
    float intensity_sum = 0.0f;
    uint32_t points = 0;
    uint32_t ground_points = 0;
    uint32_t normals = 0;
    uint32_t last_scan = 0;  // the last scan that saw it (1-based)
    uint32_t scans = 0;      // how many scans saw it
  };
  // A cube of kBlockSide^3 voxels: a dense index of its occupied voxels, which it stores compactly. A
  // scan's neighbouring pixels mostly fall into one block, so a point costs one hash lookup per block
  // change and no search within the block.
  struct Block {
    std::array<uint16_t, kBlockVoxels> slot{};  // per voxel: 1 + its index in `voxels`, 0 when empty
    std::vector<Voxel> voxels;
  };

  // A point of DriveMap::add()'s batch on its way into its voxel.
  struct PendingPoint {
    Block* block = nullptr;  // null: left out
    uint16_t cell = 0;       // within the block
    uint32_t voxel = 0;      // index into the block's voxels
    Vec3f offset;            // from the block's corner
  };
  static constexpr size_t kBatch = 32;

  bool kept(const Voxel& voxel) const;
  Block* blockFor(const Eigen::Vector3i& block_coordinates);

  MapConfig config_;
  std::unordered_map<uint64_t, Block> blocks_;
  size_t voxels_ = 0;
  size_t scans_ = 0;
  size_t outside_ = 0;
};

}  // namespace elo
