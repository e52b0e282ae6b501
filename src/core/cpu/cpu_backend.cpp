#include "core/cpu/cpu_backend.hpp"

#include "core/cpu/parallel.hpp"

#include <stdexcept>
#include <utility>

#include "elo/map/point_map.hpp"

namespace elo::cpu {

namespace {

int arenaThreads(int requested) { return requested > 0 ? requested : tbb::task_arena::automatic; }

void allocate(Model& model, const SphericalProjection& spherical, const BevProjection& bev) {
  model.nonground.resize(spherical.rows, spherical.cols);
  model.ground.resize(bev.rows, bev.cols);
  model.initialized = false;
}

}  // namespace

CpuBackend::CpuBackend(const Config& config)
    : config_(config),
      spherical_(SphericalProjection::fromConfig(config.sensor)),
      bev_(BevProjection::fromConfig(config.bev)),
      ground_band_(GroundBand::fromConfig(config.ground)),
      arena_(arenaThreads(config.runtime.threads)) {
  for (float elevation : ringElevations(config.sensor)) ring_rows_.push_back(spherical_.rowOfElevation(elevation));
  scan_.resize(spherical_.rows, spherical_.cols);
  scan_ground_.resize(bev_.rows, bev_.cols);
  allocate(model_, spherical_, bev_);
  allocate(fused_, spherical_, bev_);
  allocate(map_model_, spherical_, bev_);
  winners_.resize(scan_.image.pixelCount());
  fusion_scratch_.resize(scan_.image.pixelCount());
}

size_t CpuBackend::projectScan(const PointCloud& cloud, float stamp, const SweepMotion& motion) {
  const SweepDeskew deskew = sweepDeskew(config_.sensor, cloud, motion);
  scan_times_ = deskew.timing.source;
  scan_velocity_ = deskew.velocity;
  scan_turned_ = deskew.rotation.known != 0;
  size_t occupied = 0;
  scan_ground_built_ = false;
  arena_.execute([&] {
    occupied = projectCloud(cloud, config_.sensor, spherical_, ring_rows_, deskew, stamp, winners_, placed_, scan_);
  });
  return occupied;
}

void CpuBackend::deskewScan(const Vector6d& velocity) {
  if (scan_times_ == TimeSource::none) return;
  const SweepVelocity next = toSweepVelocity(velocity);
  scan_ground_built_ = false;
  arena_.execute([&] {
    if (scan_turned_) {
      cpu::deskewTurnedScan(scan_velocity_, next, scan_);
    } else {
      cpu::deskewScan(scan_velocity_, next, scan_);
    }
  });
  scan_velocity_ = next;
}

void CpuBackend::segmentGround() {
  scan_ground_built_ = false;
  arena_.execute([&] {
    if (config_.registration.terms == CostTerms::spherical_all) {
      labelAllNonground(scan_);
    } else {
      cpu::segmentGround(ground_band_, scan_);
    }
    ground_pixels_ = groundPixels(scan_, ground_band_);
  });
}

// The scan's ground map needs only the labels, so it is built beside the normals: where its fill runs on
// one thread (fillGroundMap()), the others work through the normals meanwhile. buildGroundMap() then has
// nothing left to do.
void CpuBackend::estimateNormals() {
  arena_.execute([&] {
    parallelInvoke(
        [&] {
          cpu::estimateNormals(config_.normals, spherical_, normal_scratch_, scan_);
          registration_pixels_ = registrationPixels(scan_);
        },
        [&] { buildScanGroundMap(); });
  });
}

void CpuBackend::buildGroundMap() {
  arena_.execute([&] { buildScanGroundMap(); });
}

// In the arena: the ground map of the scan as it is, unless it is built already.
void CpuBackend::buildScanGroundMap() {
  if (scan_ground_built_) return;
  cpu::buildGroundMap(scan_, ground_pixels_, bev_, static_cast<float>(config_.model.same_surface_distance),
                      scan_ground_scratch_, scan_ground_);
  scan_ground_built_ = true;
}

NormalEquations CpuBackend::linearize(const Eigen::Isometry3d& model_from_scan, double kernel_scale) {
  return linearizeAgainst(model_, ground_normals_, model_from_scan, kernel_scale);
}

NormalEquations CpuBackend::linearizeMap(const Eigen::Isometry3d& rendered_from_scan, double kernel_scale) {
  return linearizeAgainst(map_model_, map_ground_normals_, rendered_from_scan, kernel_scale);
}

NormalEquations CpuBackend::linearizeAgainst(const Model& model, GroundNormalCache& ground_normals,
                                             const Eigen::Isometry3d& model_from_scan, double kernel_scale) {
  NormalEquations sums;
  const CostTerms terms = config_.registration.terms;
  // The two terms' sums are independent: they run side by side, so that the end of one loop, where
  // threads run out of blocks, overlaps the other.
  arena_.execute([&] {
    parallelInvoke(
        [&] {
          if (terms == CostTerms::bev_ground) return;
          sums.nonground = nongroundSums(scan_, registration_pixels_, model.nonground, spherical_, model_from_scan,
                                         kernel_scale, config_.registration);
        },
        [&] {
          if (terms != CostTerms::fused && terms != CostTerms::bev_ground) return;
          sums.ground = groundSums(scan_ground_, model.ground, bev_, ground_normals, model_from_scan, kernel_scale,
                                   config_.registration, config_.bev);
        });
  });
  return sums;
}

void CpuBackend::updateModel(const Eigen::Isometry3d& model_from_scan, float stamp) {
  if (!model_.initialized || config_.model.mode == RegistrationMode::frame_to_frame) {
    arena_.execute([&] {
      copyScanToModel(scan_, scan_ground_, model_);
      ground_normals_.reset(model_.ground.size());
    });
    return;
  }
  const ModelFusion fusion = ModelFusion::fromConfig(config_.model, stamp);
  // The two models fuse side by side: where the ground map is filled on one thread (fillGroundMap()), the
  // others work through the spherical fusion meanwhile.
  arena_.execute([&] {
    parallelInvoke(
        [&] {
          fuseSphericalModel(model_.nonground, scan_, spherical_, model_from_scan, fusion, fusion_scratch_,
                             fused_.nonground);
        },
        [&] {
          fuseGroundModel(model_.ground, scan_ground_, bev_, model_from_scan, fusion, fused_ground_scratch_,
                          fused_.ground);
          ground_normals_.reset(fused_.ground.size());
        });
  });
  std::swap(model_, fused_);
  model_.initialized = true;
}

void CpuBackend::setMap(std::shared_ptr<const MapCloud> map) {
  if (map && !map->hasNormals() && map->size() > 0) throw std::invalid_argument("the map has no normals (prepareMap())");
  map_ = std::move(map);
  map_scratch_.closest.resize(scan_.image.pixelCount());
  map_model_.nonground.clear();
  map_model_.ground.clear();
  map_model_.initialized = false;
}

void CpuBackend::renderMap(const std::vector<int32_t>& points, const Eigen::Isometry3d& map_from_sensor) {
  if (!map_) throw std::logic_error("renderMap() before setMap()");
  const MapRendering rendering = MapRendering::fromConfig(config_);
  arena_.execute([&] {
    renderMapModel(*map_, points, toRigid3f(map_from_sensor.inverse()), spherical_, bev_, rendering, map_scratch_,
                   map_model_);
    map_ground_normals_.reset(map_model_.ground.size());
  });
}

void CpuBackend::resetModel() {
  model_.nonground.clear();
  model_.ground.clear();
  model_.initialized = false;
}

}  // namespace elo::cpu
