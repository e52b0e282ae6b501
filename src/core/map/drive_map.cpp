#include "elo/map/drive_map.hpp"

#include <algorithm>
#include <cmath>

namespace elo {
namespace {

// Block coordinates are packed 21 bits each into a 64-bit key: +-2^20 blocks along each axis.
constexpr int kKeyBits = 21;
constexpr int64_t kKeyOffset = int64_t{1} << (kKeyBits - 1);
constexpr int kMaxColumnStride = 8;
constexpr float kMaxDistance = 1000.0f;  // m from the sensor

bool packable(const Eigen::Vector3i& block) {
  return (block.array().cast<int64_t>() >= -kKeyOffset).all() && (block.array().cast<int64_t>() < kKeyOffset).all();
}

uint64_t packKey(const Eigen::Vector3i& block) {
  uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) key = (key << kKeyBits) | static_cast<uint64_t>(block[axis] + kKeyOffset);
  return key;
}

Eigen::Vector3i unpackKey(uint64_t key) {
  Eigen::Vector3i block;
  const uint64_t mask = (uint64_t{1} << kKeyBits) - 1;
  for (int axis = 2; axis >= 0; --axis, key >>= kKeyBits) {
    block[axis] = static_cast<int>(static_cast<int64_t>(key & mask) - kKeyOffset);
  }
  return block;
}

// Of a row of the range image, the columns a map scan takes at range `range`: every `stride`-th, a
// power of two up to kMaxColumnStride, where `stride` columns still span less than a voxel
// (`columns_per_voxel_metre` / range columns do), so that each voxel the row crosses keeps a point.
// Close in, where a voxel spans several columns, their points would all add to one centroid.
int columnStride(float range, float columns_per_voxel_metre) {
  int stride = 1;
  while (stride < kMaxColumnStride && 2.0f * stride * range <= columns_per_voxel_metre) stride *= 2;
  return stride;
}

}  // namespace

MapScan mapScanOf(const ScanImage& scan, const PointCloud& cloud, const Eigen::Isometry3d& pose, double stamp,
                  double voxel_size) {
  MapScan result;
  result.pose = pose;
  result.stamp = stamp;
  const SphericalImage& image = scan.image;
  const bool has_intensity = !cloud.intensity.empty();
  // Columns a voxel spans at 1 m: the voxel over the angle between neighbouring columns.
  const float columns_per_voxel_metre = static_cast<float>(voxel_size * std::max(image.cols, 1) / (2.0 * M_PI));
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      const size_t pixel = static_cast<size_t>(row) * image.cols + col;
      if (!image.occupied(pixel)) continue;
      if ((col & (columnStride(image.range[pixel], columns_per_voxel_metre) - 1)) != 0) continue;
      const Vec3f& point = image.vertex[pixel];
      // The pipeline's normals have either sign; the map's face the sensor (at the origin), so that the
      // normals of one surface seen from one side add up.
      const Vec3f& normal = image.normal[pixel];
      result.points.push_back(point);
      result.normals.push_back(normal.dot(point) > 0.0f ? Vec3f(-normal) : normal);
      const int32_t index = scan.point_index[pixel];
      const bool known = has_intensity && index >= 0 && static_cast<size_t>(index) < cloud.intensity.size();
      result.intensity.push_back(known ? cloud.intensity[index] : 0.0f);
      result.ground.push_back(scan.label[pixel] == PixelLabel::ground ? 1 : 0);
    }
  }
  return result;
}

DriveMap::DriveMap(const MapConfig& config) : config_(config) { validate(config_); }

void DriveMap::clear() {
  blocks_.clear();
  voxels_ = 0;
  scans_ = 0;
  outside_ = 0;
}

DriveMap::Block* DriveMap::blockFor(const Eigen::Vector3i& block_coordinates) {
  if (!packable(block_coordinates)) return nullptr;
  return &blocks_[packKey(block_coordinates)];
}

void DriveMap::add(const MapScan& scan) {
  const uint32_t scan_number = static_cast<uint32_t>(++scans_);
  const double block_size = config_.voxel_size * kBlockSide;
  const float voxels_per_metre = static_cast<float>(1.0 / config_.voxel_size);
  const float block_size_float = static_cast<float>(block_size);
  // The points are placed relative to the corner of the sensor's block: small numbers, which floats
  // hold to micrometres however far the drive goes.
  const Eigen::Vector3i anchor_block = (scan.pose.translation() / block_size).array().floor().cast<int>();
  const Eigen::Matrix3f rotation = scan.pose.linear().cast<float>();
  const Vec3f translation = (scan.pose.translation() - anchor_block.cast<double>() * block_size).cast<float>();
  // Neighbouring pixels mostly share a block: the last one found is tried first.
  Eigen::Vector3i last_block(0, 0, 0);
  Block* block = nullptr;
  // A voxel is mostly a cache miss, and so is its slot: the points go in batches, each step of a batch
  // first asking for the memory the next step reads, so that the misses overlap.
  std::array<PendingPoint, kBatch> batch;
  for (size_t begin = 0; begin < scan.points.size(); begin += kBatch) {
    const size_t count = std::min(kBatch, scan.points.size() - begin);
    for (size_t k = 0; k < count; ++k) {
      PendingPoint& pending = batch[k];
      pending.block = nullptr;
      const Vec3f point = rotation * scan.points[begin + k] + translation;
      // Beyond a kilometre from the sensor: not a measurement (and too far for an int voxel index).
      if (!(point.cwiseAbs().maxCoeff() < kMaxDistance)) {
        ++outside_;
        continue;
      }
      const Eigen::Vector3i voxel = (point * voxels_per_metre).array().floor().cast<int>();
      // Floor division by kBlockSide (a power of two): an arithmetic shift, also for negative indices.
      const Eigen::Vector3i relative_block(voxel.x() >> kBlockShift, voxel.y() >> kBlockShift, voxel.z() >> kBlockShift);
      if (block == nullptr || relative_block != last_block) {
        block = blockFor(anchor_block + relative_block);
        last_block = relative_block;
      }
      if (block == nullptr) {
        ++outside_;
        continue;
      }
      const Eigen::Vector3i cell = voxel - relative_block * kBlockSide;
      pending.block = block;
      pending.cell = static_cast<uint16_t>((cell.z() * kBlockSide + cell.y()) * kBlockSide + cell.x());
      pending.offset = point - relative_block.cast<float>() * block_size_float;
      __builtin_prefetch(&block->slot[pending.cell]);
    }
    for (size_t k = 0; k < count; ++k) {
      PendingPoint& pending = batch[k];
      if (pending.block == nullptr) continue;
      uint16_t& slot = pending.block->slot[pending.cell];
      if (slot == 0) {
        pending.block->voxels.emplace_back();
        slot = static_cast<uint16_t>(pending.block->voxels.size());
        ++voxels_;
      }
      pending.voxel = slot - 1u;
      __builtin_prefetch(&pending.block->voxels[pending.voxel]);
    }
    for (size_t k = 0; k < count; ++k) {
      const PendingPoint& pending = batch[k];
      if (pending.block == nullptr) continue;
      const size_t i = begin + k;
      Voxel& target = pending.block->voxels[pending.voxel];
      target.position_sum += pending.offset;
      target.intensity_sum += scan.intensity[i];
      ++target.points;
      target.ground_points += scan.ground[i];
      if (!scan.normals[i].isZero()) {
        target.normal_sum += rotation * scan.normals[i];
        ++target.normals;
      }
      if (target.last_scan != scan_number) {
        target.last_scan = scan_number;
        ++target.scans;
      }
    }
  }
}

bool DriveMap::kept(const Voxel& voxel) const {
  // Mostly ground: the road does not move, and may be seen by few scans.
  if (2 * voxel.ground_points > voxel.points) return true;
  return voxel.scans >= static_cast<uint32_t>(config_.min_observations);
}

MapCloud DriveMap::points(size_t stride) const {
  MapCloud cloud;
  const double block_size = config_.voxel_size * kBlockSide;
  size_t counter = 0;
  for (const auto& [key, block] : blocks_) {
    const Eigen::Vector3d corner = unpackKey(key).cast<double>() * block_size;
    for (const Voxel& voxel : block.voxels) {
      if (!kept(voxel) || counter++ % std::max<size_t>(stride, 1) != 0) continue;
      const Vec3f mean_offset = voxel.position_sum / static_cast<float>(voxel.points);
      cloud.points.push_back((corner + mean_offset.cast<double>()).cast<float>());
      cloud.intensity.push_back(voxel.intensity_sum / static_cast<float>(voxel.points));
      // A normal only where the voxel's normals agree: their mean is long when they point alike.
      const float length = voxel.normal_sum.norm();
      const bool consistent = voxel.normals > 0 && length > 0.5f * static_cast<float>(voxel.normals);
      cloud.normals.push_back(consistent ? Vec3f(voxel.normal_sum / length) : Vec3f::Zero());
    }
  }
  return cloud;
}

size_t DriveMap::memoryBytes() const {
  // The hash map's nodes hold the blocks; each node also carries its key, a link and its hash.
  constexpr size_t kNodeOverhead = 3 * sizeof(void*);
  size_t bytes = blocks_.bucket_count() * sizeof(void*);
  for (const auto& [key, block] : blocks_) bytes += sizeof(Block) + kNodeOverhead + block.voxels.capacity() * sizeof(Voxel);
  return bytes;
}

}  // namespace elo
