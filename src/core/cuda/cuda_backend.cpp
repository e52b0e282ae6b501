#include "core/cuda/cuda_backend.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "core/common/eigen_interop.hpp"
#include "core/common/term_sums.hpp"
#include "core/elapsed_time.hpp"
#include "elo/map/map_cloud.hpp"
#include "elo/sensor/sensor_model.hpp"

namespace elo::cuda {

namespace {

// Host and device arrays of points copy byte for byte.
static_assert(sizeof(Vec3f) == sizeof(Float3), "Eigen::Vector3f and Float3 must both be three packed floats");
static_assert(sizeof(PixelLabel) == 1, "labels copy byte for byte");

template <typename T>
void clear(const DeviceArray<T>& array, size_t count, int byte, cudaStream_t stream) {
  check(cudaMemsetAsync(array.data(), byte, count * sizeof(T), stream), "cudaMemsetAsync");
}

template <typename Host, typename Device>
void copyToHost(std::vector<Host>& host, const Device* device, size_t count, cudaStream_t stream) {
  static_assert(sizeof(Host) == sizeof(Device), "host and device elements differ in size");
  if (count == 0) return;
  check(cudaMemcpyAsync(host.data(), device, count * sizeof(Device), cudaMemcpyDeviceToHost, stream),
        "copying a buffer to the host");
}

// A copy from pageable host memory that has landed when this returns. A plain cudaMemcpy runs on the legacy
// default stream, which the backend's non-blocking streams do not wait for, and may return before the data
// reaches the device; copying on `stream` and waiting for it orders the copy before the stream's kernels.
template <typename T>
void uploadNow(const DeviceArray<T>& device, const void* host, size_t count, cudaStream_t stream, const char* what) {
  if (count == 0) return;
  check(cudaMemcpyAsync(device.data(), host, count * sizeof(T), cudaMemcpyHostToDevice, stream), what);
  check(cudaStreamSynchronize(stream), what);
}

// Refuses an allocation of `needed` bytes that the device's free memory, with the `held` bytes that are
// freed before it, cannot hold, saying what needs the memory and what the user can do instead.
void requireDeviceMemory(size_t needed, size_t held, const std::string& what) {
  size_t free_bytes = 0;
  size_t total_bytes = 0;
  check(cudaMemGetInfo(&free_bytes, &total_bytes), "cudaMemGetInfo");
  if (needed <= free_bytes + held) return;
  constexpr double kMiB = 1024.0 * 1024.0;
  throw std::runtime_error(what + " need " + std::to_string(static_cast<long>(needed / kMiB)) + " MiB on the GPU and " +
                           std::to_string(static_cast<long>((free_bytes + held) / kMiB)) +
                           " MiB are free: localize on the CPU backend, or thin the map (a coarser voxel)");
}

TermSums toTermSums(const DeviceTermSums& device) {
  return unpackTermSums(device.values, device.candidates, device.inliers);
}

}  // namespace

void CudaBackend::SphericalBuffers::allocate(size_t pixels) {
  vertices.reserve(pixels);
  normals.reserve(pixels);
  ranges.reserve(pixels);
  stamps.reserve(pixels);
}

void CudaBackend::BevBuffers::allocate(size_t grid_cells, size_t points) {
  point_of_cell.reserve(grid_cells);
  cells.reserve(points);
  vertices.reserve(points);
  ranges.reserve(points);
  stamps.reserve(points);
}

void CudaBackend::FittedGroundNormals::clear(size_t points, cudaStream_t stream) {
  cuda::clear(epochs, points, 0, stream);
  epoch = 1;
}

void CudaBackend::FittedGroundNormals::startEpoch(size_t points, cudaStream_t stream) {
  if (++epoch == 0) clear(points, stream);  // wrapped: 0 means "none fitted"
}

// Room for a render of `sources` map points (CellCompaction's per-source arrays among them); a render larger
// than the device's free memory allows is refused, saying so.
void CudaBackend::MapBuffers::reserveRender(size_t sources) {
  if (sources > indices.capacity()) {
    constexpr size_t kBytesPerSource = sizeof(int32_t) + 2 * sizeof(Float3) + 2 * sizeof(int);
    requireDeviceMemory(grownCapacity(indices.capacity(), sources) * kBytesPerSource, indices.capacity() * kBytesPerSource,
                        "the " + std::to_string(sources) + " map points of one render");
  }
  staged_indices.reserve(sources);
  indices.reserve(sources);
  source_vertices.reserve(sources);
  source_normals.reserve(sources);
  source_cells.reserve(sources);
  first_flags.reserve(sources);
  tile_firsts.reserve(compactionTiles(sources));
}

CudaBackend::CudaBackend(const Config& config)
    : config_(config),
      spherical_(SphericalProjection::fromConfig(config.sensor)),
      bev_(BevProjection::fromConfig(config.bev)),
      correction_(ElevationCorrection::fromConfig(config.sensor)),
      ground_band_(GroundBand::fromConfig(config.ground)),
      normal_params_(NormalParams::fromConfig(config.normals, spherical_)),
      gates_(CorrespondenceGates::fromConfig(config.registration)),
      pixels_(static_cast<size_t>(spherical_.rows) * spherical_.cols),
      cells_(static_cast<size_t>(bev_.rows) * bev_.cols) {
  for (float elevation : ringElevations(config.sensor)) ring_rows_.push_back(spherical_.rowOfElevation(elevation));
  check(cudaGetDevice(&device_), "cudaGetDevice");
  allocate();
  clearDevice();
}

// No copy may be reading pinned memory, nor a kernel device memory, when the buffers are freed.
CudaBackend::~CudaBackend() {
  uploads_.finish();
  cudaStreamSynchronize(upload_stream_.get());
  cudaStreamSynchronize(stream_.get());
}

void CudaBackend::allocate() {
  ring_rows_device_.reserve(ring_rows_.size());
  uploadNow(ring_rows_device_, ring_rows_.data(), ring_rows_.size(), stream_.get(), "uploading the beam rows");
  scan_image_.allocate(pixels_);
  point_indices_.reserve(pixels_);
  labels_.reserve(pixels_);
  measured_.reserve(pixels_);
  pixel_times_.reserve(pixels_);
  pixel_keys_.reserve(pixels_);
  closest_keys_.reserve(pixels_);
  pixel_surface_keys_.reserve(pixels_);
  registration_flags_.reserve(pixels_);
  registration_offsets_.reserve(pixels_);
  registration_pixels_.reserve(pixels_);
  scan_ground_.allocate(cells_, pixels_);  // one ground point per pixel at most
  for (int buffer = 0; buffer < 2; ++buffer) {
    model_image_[buffer].allocate(pixels_);
    model_ground_[buffer].allocate(cells_, cells_);  // one point per cell at most
  }
  model_ground_normals_.allocate(cells_);
  map_image_.allocate(pixels_);
  map_ground_.allocate(cells_, cells_);
  map_ground_normals_.allocate(cells_);
  // A fusion's sources are the model's points (at most one per cell) and the scan's (at most one per pixel).
  const size_t sources = cells_ + pixels_;
  cell_keys_.reserve(cells_);
  surface_keys_.reserve(cells_);
  first_sources_.reserve(cells_);
  source_cells_.reserve(sources);
  first_flags_.reserve(sources);
  tile_firsts_.reserve(compactionTiles(sources));
  scan_scratch_bytes_ = exclusiveSumScratchBytes(static_cast<int>(pixels_));  // the registration pixels
  scan_scratch_.reserve(scan_scratch_bytes_);
  counts_.reserve(kCounts);
  host_counts_.reserve(kCounts);
  partial_sums_.reserve(kTerms * kPartialRows * kReductionBlocks);
  finished_blocks_.reserve(1);
  host_term_sums_.reserve(kTerms);
  // Room for a scan of a point per pixel in both upload buffers, so that a drive's first scans do not
  // allocate (grownCapacity()); a denser sensor's grows them a few times.
  uploads_.prepareBoth([this](UploadBuffers& buffers) { buffers.reserve(pixels_); });
}

// Empty images and maps, and the compaction scratch at "none" (all bytes 0xff), as the kernels expect.
void CudaBackend::clearDevice() {
  const cudaStream_t stream = stream_.get();
  for (const SphericalBuffers* image : {&scan_image_, &model_image_[0], &model_image_[1], &map_image_}) {
    clear(image->vertices, pixels_, 0, stream);
    clear(image->normals, pixels_, 0, stream);
    clear(image->ranges, pixels_, 0, stream);
    clear(image->stamps, pixels_, 0, stream);
  }
  clear(point_indices_, pixels_, 0xff, stream);
  clear(labels_, pixels_, 0, stream);
  clear(measured_, pixels_, 0, stream);
  clear(pixel_times_, pixels_, 0, stream);
  for (const BevBuffers* map : {&scan_ground_, &model_ground_[0], &model_ground_[1], &map_ground_}) {
    clear(map->point_of_cell, cells_, 0xff, stream);
  }
  clear(closest_keys_, pixels_, 0xff, stream);
  clear(pixel_surface_keys_, pixels_, 0xff, stream);
  clear(cell_keys_, cells_, 0xff, stream);
  clear(surface_keys_, cells_, 0xff, stream);
  clear(first_sources_, cells_, 0xff, stream);
  clear(counts_, kCounts, 0, stream);
  model_ground_normals_.clear(cells_, stream);
  map_ground_normals_.clear(cells_, stream);
  // linearize()'s count of the blocks done at 0, and its partial sums initialised: its last block reads
  // (and drops) the rows of a term not summed.
  clear(finished_blocks_, 1, 0, stream);
  clear(partial_sums_, kTerms * kPartialRows * kReductionBlocks, 0, stream);
  for (int count = 0; count < kCounts; ++count) host_counts_[count] = 0;
  synchronize();
}

void CudaBackend::synchronize() { check(cudaStreamSynchronize(stream_.get()), "running the CUDA stages"); }

void CudaBackend::fetchCount(int count) {
  check(cudaMemcpyAsync(&host_counts_[count], counts_.data() + count, sizeof(int), cudaMemcpyDeviceToHost,
                        stream_.get()),
        "copying a count to the host");
}

DeviceScan CudaBackend::deviceScan() const {
  return {spherical_.rows,          spherical_.cols,           scan_image_.vertices.data(), scan_image_.normals.data(),
          scan_image_.ranges.data(), scan_image_.stamps.data(), point_indices_.data(),       labels_.data(),
          measured_.data(),          pixel_times_.data()};
}

DeviceModelImage CudaBackend::deviceImage(const SphericalBuffers& image) const {
  return {spherical_.rows, spherical_.cols, image.vertices.data(), image.normals.data(), image.ranges.data(),
          image.stamps.data()};
}

DeviceBev CudaBackend::deviceBev(const BevBuffers& buffers, int count) const {
  return {buffers.point_of_cell.data(), buffers.cells.data(),  buffers.vertices.data(),
          buffers.ranges.data(),        buffers.stamps.data(), counts_.data() + count};
}

CellCompaction CudaBackend::compaction() const {
  return {cell_keys_.data(),    surface_keys_.data(), first_sources_.data(),
          source_cells_.data(), first_flags_.data(),  tile_firsts_.data()};
}

// The per-cell arrays are "none" again after every compaction, so the map's render shares them.
CellCompaction CudaBackend::mapCompaction() const {
  return {cell_keys_.data(),          surface_keys_.data(),     first_sources_.data(),
          map_.source_cells.data(), map_.first_flags.data(), map_.tile_firsts.data()};
}

void CudaBackend::UploadBuffers::reserve(size_t points_wanted) {
  staged_points.reserve(points_wanted);
  points.reserve(points_wanted);
  staged_rings.reserve(points_wanted);
  rings.reserve(points_wanted);
  staged_times.reserve(points_wanted);
  times.reserve(points_wanted);
}

void CudaBackend::UploadBuffers::stage(const HostCloud& cloud) {
  check(cudaEventSynchronize(copied.get()), "waiting for the last copy of an upload buffer");
  check(cudaEventSynchronize(projected.get()), "waiting for the last projection of an upload buffer");
  count = cloud.count;
  has_rings = cloud.rings != nullptr;
  has_times = cloud.times != nullptr;
  if (count == 0) return;
  staged_points.reserve(count);
  points.reserve(count);
  std::memcpy(staged_points.data(), cloud.points, count * sizeof(Float3));
  if (has_rings) {
    staged_rings.reserve(count);
    rings.reserve(count);
    std::memcpy(staged_rings.data(), cloud.rings, count * sizeof(uint16_t));
  }
  if (has_times) {
    staged_times.reserve(count);
    times.reserve(count);
    std::memcpy(staged_times.data(), cloud.times, count * sizeof(float));
  }
}

void CudaBackend::UploadBuffers::copy(cudaStream_t stream) {
  if (count == 0) return;
  check(cudaMemcpyAsync(points.data(), staged_points.data(), count * sizeof(Float3), cudaMemcpyHostToDevice, stream),
        "uploading the cloud");
  if (has_rings) {
    check(cudaMemcpyAsync(rings.data(), staged_rings.data(), count * sizeof(uint16_t), cudaMemcpyHostToDevice, stream),
          "uploading the rings");
  }
  if (has_times) {
    check(cudaMemcpyAsync(times.data(), staged_times.data(), count * sizeof(float), cudaMemcpyHostToDevice, stream),
          "uploading the per-point times");
  }
}

CudaBackend::HostCloud CudaBackend::hostCloud(const PointCloud& cloud, bool with_times) const {
  const size_t count = cloud.points.size();
  const bool with_rings = !ring_rows_.empty() && cloud.ring.size() == count;
  return {cloud.points.data(), with_rings ? cloud.ring.data() : nullptr, with_times ? cloud.time.data() : nullptr,
          count};
}

// The cloud's times go up when the odometry may deskew by them. The staging thread reads the cloud's
// arrays, not the PointCloud, which the caller may move meanwhile.
void CudaBackend::prefetch(const PointCloud& cloud) {
  const bool with_times = config_.deskew.time_source == TimeSource::field && cloud.time.size() == cloud.points.size();
  const HostCloud host = hostCloud(cloud, with_times);
  uploads_.prefetch(CloudIdentity::of(cloud), with_times, [this, host](UploadBuffers& buffers) {
    check(cudaSetDevice(device_), "selecting the device");
    buffers.stage(host);
    buffers.copy(upload_stream_.get());
    check(cudaEventRecord(buffers.copied.get(), upload_stream_.get()), "cudaEventRecord");
  });
}

void CudaBackend::finishPrefetch() noexcept {
  const Clock::time_point wait_start = Clock::now();
  uploads_.finish();
  upload_milliseconds_ += millisecondsSince(wait_start);
}

// A prefetched cloud: the stream waits for its copy, between two events that time the wait. Any other
// cloud is staged here and copied on the stream between the two events.
const CudaBackend::UploadBuffers& CudaBackend::upload(const PointCloud& cloud, bool with_times) {
  const cudaStream_t stream = stream_.get();
  const Clock::time_point start = Clock::now();
  const auto taken = uploads_.take(CloudIdentity::of(cloud), with_times);
  UploadBuffers& buffers = taken.buffers;
  if (!taken.prefetched) buffers.stage(hostCloud(cloud, with_times));
  upload_milliseconds_ = millisecondsSince(start);
  check(cudaEventRecord(upload_start_.get(), stream), "cudaEventRecord");
  if (taken.prefetched) {
    check(cudaStreamWaitEvent(stream, buffers.copied.get(), 0), "waiting for the prefetched upload");
  } else {
    buffers.copy(stream);
  }
  check(cudaEventRecord(upload_end_.get(), stream), "cudaEventRecord");
  return buffers;
}

size_t CudaBackend::projectScan(const PointCloud& cloud, float stamp, const SweepMotion& motion) {
  SweepDeskew deskew = sweepDeskew(config_.sensor, cloud, motion);
  const bool with_times = deskew.timing.source == TimeSource::field;
  const UploadBuffers& buffers = upload(cloud, with_times);
  deskew.times = with_times ? buffers.times.data() : nullptr;
  scan_times_ = deskew.timing.source;
  scan_velocity_ = deskew.velocity;
  scan_turned_ = deskew.rotation.known != 0;
  const UploadedCloud uploaded{buffers.points.data(), buffers.has_rings ? buffers.rings.data() : nullptr,
                               static_cast<int>(buffers.count)};
  cuda::projectScan(uploaded, spherical_, correction_, deskew, ring_rows_device_.data(),
                    static_cast<int>(ring_rows_.size()), stamp, pixel_keys_.data(), deviceScan(),
                    counts_.data() + kOccupiedPixels, stream_.get());
  check(cudaEventRecord(buffers.projected.get(), stream_.get()), "cudaEventRecord");
  fetchCount(kOccupiedPixels);
  synchronize();  // the caller needs the count
  float copy_milliseconds = 0.0f;
  check(cudaEventElapsedTime(&copy_milliseconds, upload_start_.get(), upload_end_.get()), "cudaEventElapsedTime");
  upload_milliseconds_ += copy_milliseconds;
  scan_view_current_ = false;
  return static_cast<size_t>(host_counts_[kOccupiedPixels]);
}

void CudaBackend::deskewScan(const Vector6d& velocity) {
  if (scan_times_ == TimeSource::none) return;
  const SweepVelocity next = toSweepVelocity(velocity);
  if (scan_turned_) {
    cuda::deskewTurnedScan(deviceScan(), scan_velocity_, next, stream_.get());
  } else {
    cuda::deskewScan(deviceScan(), scan_velocity_, next, stream_.get());
  }
  scan_velocity_ = next;
  scan_view_current_ = false;
}

void CudaBackend::segmentGround() {
  if (config_.registration.terms == CostTerms::spherical_all) {
    cuda::labelAllNonground(deviceScan(), stream_.get());
  } else {
    cuda::segmentGround(deviceScan(), ground_band_, stream_.get());
  }
  scan_view_current_ = false;
}

void CudaBackend::estimateNormals() {
  const FlaggedList registration{registration_flags_.data(),  registration_offsets_.data(),
                                 registration_pixels_.data(), counts_.data() + kRegistrationPixels,
                                 scan_scratch_.data(),        scan_scratch_bytes_};
  cuda::estimateNormals(deviceScan(), normal_params_, registration, stream_.get());
  scan_view_current_ = false;
}

void CudaBackend::buildGroundMap() {
  cuda::buildGroundMap(deviceScan(), ground_band_, bev_, static_cast<float>(config_.model.same_surface_distance),
                       scanGroundMap(), compaction(), stream_.get());
  scan_ground_view_current_ = false;
}

NormalEquations CudaBackend::linearize(const Eigen::Isometry3d& model_from_scan, double kernel_scale) {
  return linearizeAgainst(deviceModel(current_), modelGroundMap(current_), model_ground_normals_.cache(),
                          model_from_scan, kernel_scale);
}

NormalEquations CudaBackend::linearizeAgainst(const DeviceModelImage& model, const DeviceBev& model_ground,
                                              const GroundNormalCache& ground_normals,
                                              const Eigen::Isometry3d& model_from_scan, double kernel_scale) {
  const CostTerms terms = config_.registration.terms;
  LinearizeInputs inputs{};
  inputs.nonground = terms != CostTerms::bev_ground;
  inputs.ground = terms == CostTerms::fused || terms == CostTerms::bev_ground;
  inputs.scan = deviceScan();
  inputs.registration_pixels = registration_pixels_.data();
  inputs.registration_count = counts_.data() + kRegistrationPixels;
  inputs.model = model;
  inputs.spherical = spherical_;
  inputs.scan_ground = scanGroundMap();
  inputs.model_ground = model_ground;
  inputs.bev = bev_;
  inputs.ground_normals = ground_normals;
  inputs.normal_neighbours = config_.bev.normal_neighbours;
  inputs.patch_radius = config_.bev.normal_patch_radius;
  inputs.gates = gates_;
  inputs.motion = toRigid3f(model_from_scan);
  inputs.kernel_scale = kernel_scale;
  inputs.near_weight_range = static_cast<float>(config_.registration.near_weight_range);
  // The launch writes the sums into host_term_sums_ itself: one synchronisation and no copy.
  cuda::linearize(inputs, {partial_sums_.data(), finished_blocks_.data()}, host_term_sums_.data(), stream_.get());
  synchronize();
  NormalEquations sums;
  sums.nonground = toTermSums(host_term_sums_[0]);
  sums.ground = toTermSums(host_term_sums_[1]);
  return sums;
}

void CudaBackend::updateModel(const Eigen::Isometry3d& model_from_scan, float stamp) {
  const cudaStream_t stream = stream_.get();
  if (!model_initialized_ || config_.model.mode == RegistrationMode::frame_to_frame) {
    cuda::copyScanToModel(deviceScan(), deviceModel(current_), stream);
    cuda::copyGroundMap(scanGroundMap(), modelGroundMap(current_), stream);
  } else {
    const Rigid3f scan_from_model = toRigid3f(model_from_scan.inverse());
    const ModelFusion fusion = ModelFusion::fromConfig(config_.model, stamp);
    const int next = 1 - current_;
    cuda::fuseSphericalModel(deviceModel(current_), deviceScan(), spherical_, scan_from_model, fusion,
                             closest_keys_.data(), pixel_surface_keys_.data(), deviceModel(next), stream);
    cuda::fuseGroundModel(modelGroundMap(current_), scanGroundMap(), bev_, scan_from_model, fusion,
                          modelGroundMap(next), compaction(), stream);
    current_ = next;
  }
  model_initialized_ = true;
  model_ground_normals_.startEpoch(cells_, stream);
  model_view_current_ = false;
}

void CudaBackend::resetModel() {
  const cudaStream_t stream = stream_.get();
  clear(model_image_[current_].ranges, pixels_, 0, stream);
  clear(model_image_[current_].normals, pixels_, 0, stream);
  cuda::clearGroundMap(modelGroundMap(current_), stream);
  model_ground_normals_.startEpoch(cells_, stream);
  model_initialized_ = false;
  model_view_current_ = false;
}

const ScanImage& CudaBackend::scan() {
  if (scan_view_current_) return scan_view_;
  if (scan_view_.label.empty()) scan_view_.resize(spherical_.rows, spherical_.cols);
  const cudaStream_t stream = stream_.get();
  copyToHost(scan_view_.image.vertex, scan_image_.vertices.data(), pixels_, stream);
  copyToHost(scan_view_.image.normal, scan_image_.normals.data(), pixels_, stream);
  copyToHost(scan_view_.image.range, scan_image_.ranges.data(), pixels_, stream);
  copyToHost(scan_view_.image.stamp, scan_image_.stamps.data(), pixels_, stream);
  copyToHost(scan_view_.point_index, point_indices_.data(), pixels_, stream);
  copyToHost(scan_view_.label, labels_.data(), pixels_, stream);
  copyToHost(scan_view_.measured, measured_.data(), pixels_, stream);
  copyToHost(scan_view_.time, pixel_times_.data(), pixels_, stream);
  synchronize();
  scan_view_current_ = true;
  return scan_view_;
}

// The compact arrays as they are on the device, and the grid rebuilt from them: the device grid holds
// the index of each point at its cell and -1 everywhere else, and so does the view.
void CudaBackend::copyBevView(const BevBuffers& buffers, int points, BevImage& view) {
  if (view.point_of_cell.empty()) view.resize(bev_.rows, bev_.cols);
  view.clear();
  view.cell.resize(points);
  view.vertex.resize(points);
  view.range.resize(points);
  view.stamp.resize(points);
  const cudaStream_t stream = stream_.get();
  copyToHost(view.cell, buffers.cells.data(), points, stream);
  copyToHost(view.vertex, buffers.vertices.data(), points, stream);
  copyToHost(view.range, buffers.ranges.data(), points, stream);
  copyToHost(view.stamp, buffers.stamps.data(), points, stream);
  synchronize();
  for (int point = 0; point < points; ++point) view.point_of_cell[view.cell[point]] = point;
}

const BevImage& CudaBackend::scanGround() {
  if (scan_ground_view_current_) return scan_ground_view_;
  fetchCount(kScanGroundPoints);
  synchronize();
  copyBevView(scan_ground_, host_counts_[kScanGroundPoints], scan_ground_view_);
  scan_ground_view_current_ = true;
  return scan_ground_view_;
}

void CudaBackend::copyModelView(const SphericalBuffers& image, const BevBuffers& ground, int ground_points,
                                Model& view) {
  if (view.nonground.range.empty()) view.nonground.resize(spherical_.rows, spherical_.cols);
  const cudaStream_t stream = stream_.get();
  copyToHost(view.nonground.vertex, image.vertices.data(), pixels_, stream);
  copyToHost(view.nonground.normal, image.normals.data(), pixels_, stream);
  copyToHost(view.nonground.range, image.ranges.data(), pixels_, stream);
  copyToHost(view.nonground.stamp, image.stamps.data(), pixels_, stream);
  fetchCount(ground_points);
  synchronize();  // the count, before the points are copied
  copyBevView(ground, host_counts_[ground_points], view.ground);
}

const Model& CudaBackend::model() {
  if (model_view_current_) return model_view_;
  copyModelView(model_image_[current_], model_ground_[current_], kModelPoints + current_, model_view_);
  model_view_.initialized = model_initialized_;
  model_view_current_ = true;
  return model_view_;
}

void CudaBackend::setMap(std::shared_ptr<const MapCloud> map) {
  if (map && !map->hasNormals() && map->size() > 0) {
    throw std::invalid_argument("the map has no normals (prepareMap())");
  }
  synchronize();  // no kernel reads the map being replaced
  clearMapModel();
  map_residency_.reset();  // it refers to the map
  map_cloud_ = std::move(map);
  if (map_cloud_) map_residency_ = std::make_unique<MapResidency>(*map_cloud_, config_.localization.tile_size);
}

void CudaBackend::holdMapAround(const std::vector<int32_t>& points) {
  map_residency_->holdAround(points);
  try {
    uploadHeldMap();
  } catch (...) {
    map_residency_->release();  // what it says it holds is not all on the device
    throw;
  }
}

// The held points and their normals, 24 bytes a point. A part that does not fit in the device's free
// memory is refused, saying how much it needs.
void CudaBackend::uploadHeldMap() {
  const std::vector<int32_t>& held = map_residency_->held();
  const size_t count = held.size();
  // The smaller of the two: an allocation that failed halfway leaves the normals shorter.
  const size_t capacity = std::min(map_.points.capacity(), map_.normals.capacity());
  if (count > capacity) {
    requireDeviceMemory(grownCapacity(capacity, count) * 2 * sizeof(Float3), capacity * 2 * sizeof(Float3),
                        "the " + std::to_string(count) + " map points near the vehicle");
    map_.points.reserve(count);
    map_.normals.reserve(count);
  }
  std::vector<Vec3f> points(count);
  std::vector<Vec3f> normals(count);
  for (size_t slot = 0; slot < count; ++slot) {
    points[slot] = map_cloud_->points[held[slot]];
    normals[slot] = map_cloud_->normals[held[slot]];
  }
  const cudaStream_t stream = stream_.get();
  uploadNow(map_.points, points.data(), count, stream, "uploading the map's points");
  uploadNow(map_.normals, normals.data(), count, stream, "uploading the map's normals");
}

// Before the first render, and after a new map: an empty model.
void CudaBackend::clearMapModel() {
  const cudaStream_t stream = stream_.get();
  clear(map_image_.ranges, pixels_, 0, stream);
  clear(map_image_.normals, pixels_, 0, stream);
  cuda::clearGroundMap(mapGroundMap(), stream);
  map_ground_normals_.startEpoch(cells_, stream);
  map_rendered_ = false;
  map_model_view_current_ = false;
}

void CudaBackend::renderMap(const std::vector<int32_t>& points, const Eigen::Isometry3d& map_from_sensor) {
  if (!map_residency_) throw std::logic_error("renderMap() before setMap()");
  const cudaStream_t stream = stream_.get();
  synchronize();  // the last render's copy has read the staged places, and no kernel reads the held map
  map_.reserveRender(points.size());
  int32_t* const places = map_.staged_indices.data();
  if (!map_residency_->locate(points, places)) {
    holdMapAround(points);
    map_residency_->locate(points, places);
  }
  if (!points.empty()) {
    check(cudaMemcpyAsync(map_.indices.data(), places, points.size() * sizeof(int32_t), cudaMemcpyHostToDevice,
                          stream),
          "uploading the places of the map points to render");
  }
  const MapRenderSources sources{map_.indices.data(), static_cast<int>(points.size()), map_.source_vertices.data(),
                                 map_.source_normals.data()};
  cuda::renderMapModel({map_.points.data(), map_.normals.data()}, sources, toRigid3f(map_from_sensor.inverse()),
                       spherical_, bev_, MapRendering::fromConfig(config_), closest_keys_.data(),
                       deviceImage(map_image_), mapGroundMap(), mapCompaction(), stream);
  map_ground_normals_.startEpoch(cells_, stream);
  map_rendered_ = true;
  map_model_view_current_ = false;
}

NormalEquations CudaBackend::linearizeMap(const Eigen::Isometry3d& rendered_from_scan, double kernel_scale) {
  return linearizeAgainst(deviceImage(map_image_), mapGroundMap(), map_ground_normals_.cache(), rendered_from_scan,
                          kernel_scale);
}

const Model& CudaBackend::mapModel() {
  if (map_model_view_current_) return map_model_view_;
  copyModelView(map_image_, map_ground_, kMapGroundPoints, map_model_view_);
  map_model_view_.initialized = map_rendered_;
  map_model_view_current_ = true;
  return map_model_view_;
}

}  // namespace elo::cuda
