// The CUDA implementation of the backend interface: the stages of src/core/cuda/*.cu, queued on one
// stream over device buffers that mirror include/elo/types.hpp and are allocated once, in the
// constructor, the upload's for a point per pixel. Only the upload grows, by half (grownCapacity()), when
// a scan has more points than it holds, and so do localization's map and render buffers, with the
// largest part of the map held and the largest render. The scan goes up through pinned memory, in one of
// two upload buffers: the next scan, when prefetched, is staged into the other one on a thread of its own
// and copied on a stream of its own while this one is processed. The host views are copied back when
// asked for, and only when the device buffers changed since.
#pragma once

#include <memory>
#include <vector>

#include "core/cuda/device_buffer.hpp"
#include "core/double_buffered_upload.hpp"
#include "core/cuda/kernels.hpp"
#include "core/map/map_residency.hpp"
#include "elo/pipeline/backend.hpp"

namespace elo::cuda {

class CudaBackend final : public Backend {
 public:
  explicit CudaBackend(const Config& config);
  ~CudaBackend() override;

  const char* name() const override { return "cuda"; }
  size_t projectScan(const PointCloud& cloud, float stamp, const SweepMotion& motion) override;
  void deskewScan(const Vector6d& velocity) override;
  void segmentGround() override;
  void estimateNormals() override;
  void buildGroundMap() override;
  NormalEquations linearize(const Eigen::Isometry3d& model_from_scan, double kernel_scale) override;
  void updateModel(const Eigen::Isometry3d& model_from_scan, float stamp) override;
  void resetModel() override;

  const ScanImage& scan() override;
  const BevImage& scanGround() override;
  const Model& model() override;

  // Localization (renderMap()): the device holds the map's tiles near the renders (MapResidency), copied
  // up when a render needs one it does not hold; a render uploads the places of the points it draws.
  void setMap(std::shared_ptr<const MapCloud> map) override;
  void renderMap(const std::vector<int32_t>& points, const Eigen::Isometry3d& map_from_sensor) override;
  NormalEquations linearizeMap(const Eigen::Isometry3d& rendered_from_scan, double kernel_scale) override;
  const Model& mapModel() override;

  void synchronize() override;
  void prefetch(const PointCloud& cloud) override;
  void finishPrefetch() noexcept override;
  double lastUploadMilliseconds() const override { return upload_milliseconds_; }

 private:
  struct SphericalBuffers {
    DeviceArray<Float3> vertices;
    DeviceArray<Float3> normals;
    DeviceArray<float> ranges;
    DeviceArray<float> stamps;

    void allocate(size_t pixels);
  };
  struct BevBuffers {
    DeviceArray<int32_t> point_of_cell;
    DeviceArray<int32_t> cells;
    DeviceArray<Float3> vertices;
    DeviceArray<float> ranges;
    DeviceArray<float> stamps;

    void allocate(size_t grid_cells, size_t points);
  };
  // The normals of a ground map's points fitted so far (GroundNormalCache), a slot per point; a new epoch
  // for every change of the map makes them all stale at once.
  struct FittedGroundNormals {
    DeviceArray<Float3> normals;
    DeviceArray<unsigned> epochs;
    unsigned epoch = 1;

    void allocate(size_t points) {
      normals.reserve(points);
      epochs.reserve(points);
    }
    void clear(size_t points, cudaStream_t stream);  // every epoch 0: none fitted
    void startEpoch(size_t points, cudaStream_t stream);
    GroundNormalCache cache() const { return {normals.data(), epochs.data(), epoch}; }
  };
  // The part of localization's map the device holds (MapResidency::held()), and one render's sources: the
  // places there of the points drawn, staged and on the device, their vertices and normals in the
  // sensor's frame, and the cell compaction's per-source arrays. They grow with the largest part held and
  // the largest render.
  struct MapBuffers {
    DeviceArray<Float3> points;
    DeviceArray<Float3> normals;
    PinnedArray<int32_t> staged_indices;
    DeviceArray<int32_t> indices;
    DeviceArray<Float3> source_vertices;
    DeviceArray<Float3> source_normals;
    DeviceArray<int> source_cells;
    DeviceArray<int> first_flags;
    DeviceArray<int> tile_firsts;

    void reserveRender(size_t sources);
  };
  // The counts the kernels write, at these indices of counts_ (and host_counts_, their pinned copy); the
  // point counts of the two model buffers are at kModelPoints and kModelPoints + 1.
  enum Count {
    kOccupiedPixels,
    kRegistrationPixels,
    kScanGroundPoints,
    kMapGroundPoints,
    kModelPoints,
    kCounts = kModelPoints + 2
  };

  // A cloud's arrays as an upload reads them; `rings` and `times` are null when they do not go up.
  struct HostCloud {
    const Vec3f* points = nullptr;
    const uint16_t* rings = nullptr;
    const float* times = nullptr;
    size_t count = 0;
  };
  // One scan's upload (DoubleBufferedUpload): the cloud staged in pinned memory and copied to the device.
  // Staging waits until the copy that read the pinned memory last (`copied`) and the projection that read
  // the device copy last (`projected`) are done.
  struct UploadBuffers {
    PinnedArray<Float3> staged_points;
    PinnedArray<uint16_t> staged_rings;
    PinnedArray<float> staged_times;
    DeviceArray<Float3> points;
    DeviceArray<uint16_t> rings;
    DeviceArray<float> times;
    Event copied{cudaEventDisableTiming};
    Event projected{cudaEventDisableTiming};
    // The points staged, and whether their rings and times are there.
    size_t count = 0;
    bool has_rings = false;
    bool has_times = false;

    // Room for a cloud of `points_wanted` points, with rings and times.
    void reserve(size_t points_wanted);
    // Copies `cloud` into the pinned memory, growing the buffers as needed.
    void stage(const HostCloud& cloud);
    // Queues the copy of the staged cloud to the device on `stream`.
    void copy(cudaStream_t stream);
  };

  void allocate();
  void clearDevice();
  HostCloud hostCloud(const PointCloud& cloud, bool with_times) const;
  // Uploads the points, their rings when the projection uses them and their times when `with_times`, or
  // waits for their prefetched upload; returns the buffers that hold them on the device. Records
  // upload_start_ and upload_end_ on the stream around the copy, or the wait for it.
  const UploadBuffers& upload(const PointCloud& cloud, bool with_times);
  DeviceScan deviceScan() const;
  DeviceModelImage deviceModel(int buffer) const { return deviceImage(model_image_[buffer]); }
  DeviceModelImage deviceImage(const SphericalBuffers& image) const;
  DeviceBev deviceBev(const BevBuffers& buffers, int count) const;
  DeviceBev scanGroundMap() const { return deviceBev(scan_ground_, kScanGroundPoints); }
  DeviceBev modelGroundMap(int buffer) const { return deviceBev(model_ground_[buffer], kModelPoints + buffer); }
  DeviceBev mapGroundMap() const { return deviceBev(map_ground_, kMapGroundPoints); }
  CellCompaction compaction() const;
  // The same, with the map render's per-source arrays.
  CellCompaction mapCompaction() const;
  // Holds the map's tiles around `points` and copies them up; on a failure, holds nothing.
  void holdMapAround(const std::vector<int32_t>& points);
  void uploadHeldMap();
  void clearMapModel();
  // The Gauss-Newton sums of the scan against a model: the fused one or the map's.
  NormalEquations linearizeAgainst(const DeviceModelImage& model, const DeviceBev& model_ground,
                                   const GroundNormalCache& ground_normals, const Eigen::Isometry3d& model_from_scan,
                                   double kernel_scale);
  // Copies count `count` into host_counts_ once the stream gets there.
  void fetchCount(int count);
  void copyBevView(const BevBuffers& buffers, int points, BevImage& view);
  void copyModelView(const SphericalBuffers& image, const BevBuffers& ground, int ground_points, Model& view);

  Config config_;
  SphericalProjection spherical_;
  BevProjection bev_;
  ElevationCorrection correction_;
  GroundBand ground_band_;
  NormalParams normal_params_;
  CorrespondenceGates gates_;
  size_t pixels_;
  size_t cells_;
  std::vector<int> ring_rows_;

  int device_ = 0;  // the thread that stages prefetched uploads works on it too
  Stream stream_;
  Stream upload_stream_;  // the prefetched uploads' copies
  Event upload_start_;
  Event upload_end_;
  double upload_milliseconds_ = 0.0;
  DeviceArray<int> ring_rows_device_;

  // The scan image, its registration pixels and its ground map.
  SphericalBuffers scan_image_;
  DeviceArray<int32_t> point_indices_;
  DeviceArray<PixelLabel> labels_;
  DeviceArray<Float3> measured_;
  DeviceArray<float> pixel_times_;
  // The scan's deskew: whether its points have times, the velocity its vertices are deskewed under and
  // whether a gyro's rotation turned them (it then stays through every deskew after the projection).
  TimeSource scan_times_ = TimeSource::none;
  SweepVelocity scan_velocity_{};
  bool scan_turned_ = false;
  DeviceArray<ClosestKey> pixel_keys_;
  DeviceArray<ClosestKey> closest_keys_;        // the model update's first round
  DeviceArray<ClosestKey> pixel_surface_keys_;  // ... and its second
  DeviceArray<int> registration_flags_;
  DeviceArray<int> registration_offsets_;
  DeviceArray<int> registration_pixels_;
  BevBuffers scan_ground_;

  // The model, twice: an update writes the buffer not in use (`1 - current_`), then switches to it.
  SphericalBuffers model_image_[2];
  BevBuffers model_ground_[2];
  // The current model's ground normals, fitted when first matched; a new epoch for every model.
  FittedGroundNormals model_ground_normals_;
  int current_ = 0;
  bool model_initialized_ = false;

  // Localization: the map, the part of it held on the device, the model last rendered from it and its
  // ground normals.
  std::shared_ptr<const MapCloud> map_cloud_;
  std::unique_ptr<MapResidency> map_residency_;  // null: no map set
  MapBuffers map_;
  SphericalBuffers map_image_;
  BevBuffers map_ground_;
  FittedGroundNormals map_ground_normals_;
  bool map_rendered_ = false;

  // Scratch of the BEV compaction (sources: every model point and every scan pixel).
  DeviceArray<ClosestKey> cell_keys_;
  DeviceArray<ClosestKey> surface_keys_;
  DeviceArray<uint32_t> first_sources_;
  DeviceArray<int> source_cells_;
  DeviceArray<int> first_flags_;
  DeviceArray<int> tile_firsts_;
  // The scan of the registration pixels' flags (estimateNormals()).
  size_t scan_scratch_bytes_ = 0;
  DeviceArray<unsigned char> scan_scratch_;

  DeviceArray<int> counts_;
  PinnedArray<int> host_counts_;
  DeviceArray<double> partial_sums_;       // linearize()'s scratch
  DeviceArray<unsigned> finished_blocks_;  // 0 between launches
  PinnedArray<DeviceTermSums> host_term_sums_;

  // Host views, filled on demand.
  ScanImage scan_view_;
  BevImage scan_ground_view_;
  Model model_view_;
  Model map_model_view_;
  bool scan_view_current_ = false;
  bool scan_ground_view_current_ = false;
  bool model_view_current_ = false;
  bool map_model_view_current_ = false;

  // The scans' uploads: a prefetched cloud is staged on the uploads' own thread and copied on
  // upload_stream_, any other one here and on stream_. Last: its thread stops before the streams go.
  DoubleBufferedUpload<UploadBuffers> uploads_;
};

}  // namespace elo::cuda
