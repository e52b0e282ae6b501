// The ELO pipeline (Fig. 2): predict -> project -> segment ground -> normals -> BEV -> register ->
// update the model. ROS-free; the nodelet and the tools are thin shells around this class.
#pragma once

#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <string>

#include "elo/backend.hpp"
#include "elo/config.hpp"
#include "elo/motion_prior.hpp"
#include "elo/registration.hpp"

namespace elo {

// Wall time of each stage (ms), split as the paper's Table V.
struct StageTimes {
  double projection = 0.0;
  double feature_extraction = 0.0;  // ground segmentation + normals + BEV map
  double registration = 0.0;
  double model_update = 0.0;
  double total = 0.0;
};

struct FrameResult {
  bool processed = false;
  std::string skip_reason;  // why the scan was not used, when !processed
  bool reset = false;       // the odometry restarted at this scan (time went backwards)
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();   // sensor in the odometry frame
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();  // T^{t-1}_t
  RegistrationResult registration;
  StageTimes times;
};

class Odometry {
 public:
  // Throws ConfigError for an unusable config and std::runtime_error for an unavailable backend.
  explicit Odometry(const Config& config);

  // Processes one sweep. A scan that cannot be used (empty, too few valid points, a stamp that is not
  // finite or repeats the last one) is skipped, counted under its reason and leaves the state as it was.
  FrameResult process(const PointCloud& cloud);

  // Forgets the model, the motion and the pose: the next scan starts a new trajectory at identity.
  void reset();

  const Eigen::Isometry3d& pose() const { return pose_; }
  const Config& config() const { return config_; }
  Backend& backend() { return *backend_; }
  size_t processedCount() const { return processed_; }
  const std::map<std::string, size_t>& skippedCounts() const { return skipped_; }

  // A scan with fewer occupied pixels than this is skipped: nothing reliable can be registered.
  static constexpr size_t kMinOccupiedPixels = 100;

 private:
  FrameResult skip(const std::string& reason);

  Config config_;
  std::unique_ptr<Backend> backend_;
  MotionModel motion_;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  bool started_ = false;
  double first_stamp_ = 0.0;
  double last_stamp_ = 0.0;
  size_t processed_ = 0;
  std::map<std::string, size_t> skipped_;
};

}  // namespace elo
