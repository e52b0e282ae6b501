// The threaded CPU implementation of the backend interface.
#pragma once

#include <tbb/task_arena.h>

#include "core/cpu/stages.hpp"

namespace elo::cpu {

class CpuBackend final : public Backend {
 public:
  explicit CpuBackend(const Config& config);

  const char* name() const override { return "cpu"; }
  size_t projectScan(const PointCloud& cloud, float stamp, const SweepMotion& motion) override;
  void deskewScan(const Vector6d& velocity) override;
  void segmentGround() override;
  void estimateNormals() override;
  void buildGroundMap() override;
  NormalEquations linearize(const Eigen::Isometry3d& model_from_scan, double kernel_scale) override;
  void updateModel(const Eigen::Isometry3d& model_from_scan, float stamp) override;
  void resetModel() override;

  const ScanImage& scan() override { return scan_; }
  const BevImage& scanGround() override { return scan_ground_; }
  const Model& model() override { return model_; }

  void setMap(std::shared_ptr<const MapCloud> map) override;
  void renderMap(const std::vector<int32_t>& points, const Eigen::Isometry3d& map_from_sensor) override;
  NormalEquations linearizeMap(const Eigen::Isometry3d& rendered_from_scan, double kernel_scale) override;
  const Model& mapModel() override { return map_model_; }

 private:
  void buildScanGroundMap();
  // The sums of the scan moved by `model_from_scan` against `model`, whose BEV normals `ground_normals` keeps.
  NormalEquations linearizeAgainst(const Model& model, GroundNormalCache& ground_normals,
                                   const Eigen::Isometry3d& model_from_scan, double kernel_scale);

  Config config_;
  SphericalProjection spherical_;
  BevProjection bev_;
  GroundBand ground_band_;  // the ground band of config_.ground, built once
  std::vector<int> ring_rows_;
  tbb::task_arena arena_;

  ScanImage scan_;
  // The scan's deskew: whether its points have times, the velocity its vertices are deskewed under and
  // whether a gyro's rotation turned them (it then stays through every deskew after the projection).
  TimeSource scan_times_ = TimeSource::none;
  SweepVelocity scan_velocity_{};
  bool scan_turned_ = false;
  std::vector<int32_t> registration_pixels_;  // non-ground pixels with a normal
  std::vector<int32_t> ground_pixels_;  // as labelled; the ground map is built (and rebuilt) from them
  // Each ground map its own scratch: its arrays then keep about their size from frame to frame, and a
  // resize seldom has new elements to initialise.
  GroundMapScratch scan_ground_scratch_;
  GroundMapScratch fused_ground_scratch_;
  BevImage scan_ground_;
  bool scan_ground_built_ = false;  // for the scan's vertices and labels as they are
  Model model_;
  Model fused_;  // the model update writes here, then swaps with model_
  ClosestWins winners_;  // the projection's closest point per pixel
  std::vector<ScanPoint> placed_;  // the projection's cloud points as placed (corrected, deskewed, timed)
  SphericalFusionScratch fusion_scratch_;
  NormalScratch normal_scratch_;
  GroundNormalCache ground_normals_;

  // Localization (renderMap()): the map, the model last rendered from it and their scratch.
  std::shared_ptr<const MapCloud> map_;
  Model map_model_;
  MapRenderScratch map_scratch_;
  GroundNormalCache map_ground_normals_;
};

}  // namespace elo::cpu
