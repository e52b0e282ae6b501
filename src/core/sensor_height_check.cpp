#include "elo/sensor/sensor_height_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <Eigen/Dense>

#include "core/median.hpp"

namespace elo {
namespace {

constexpr double kNearest = 2.0;   // m horizontally: closer returns hit the platform or the person
constexpr double kFarthest = 12.0; // m: beyond it a tilted sensor's ground no longer lies below it
constexpr double kBelow = -0.2;    // m: only points this far below the sensor
constexpr double kMaxTiltCos = 0.866;  // cos 30 deg
constexpr double kInlierDistance = 0.08;  // m from the plane
constexpr double kMinInlierShare = 0.3;   // of the candidate points, for a plane to be the ground
constexpr size_t kMinPoints = 50;
constexpr int kTrials = 60;
// Scans whose ground heights make the median: a few, so that a kerb or a ramp in one scan does not warn.
constexpr size_t kRecentScans = 5;

// The points the ground is fitted to.
std::vector<Eigen::Vector3d> pointsBelow(const PointCloud& cloud, size_t stride) {
  std::vector<Eigen::Vector3d> points;
  for (size_t i = 0; i < cloud.points.size(); i += std::max<size_t>(stride, 1)) {
    const Eigen::Vector3d p = cloud.points[i].cast<double>();
    const double horizontal = std::hypot(p.x(), p.y());
    if (p.allFinite() && p.z() < kBelow && horizontal >= kNearest && horizontal <= kFarthest) points.push_back(p);
  }
  return points;
}

struct Plane {
  Eigen::Vector3d normal;  // unit, pointing up (z >= 0)
  double offset;           // normal . p + offset = 0 on the plane; the sensor's height above it
};

std::optional<Plane> planeThrough(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  Eigen::Vector3d normal = (b - a).cross(c - a);
  if (normal.norm() < 1e-6) return std::nullopt;
  normal.normalize();
  if (normal.z() < 0.0) normal = -normal;
  if (normal.z() < kMaxTiltCos) return std::nullopt;
  return Plane{normal, -normal.dot(a)};
}

// The least-squares plane of the points within kInlierDistance of `plane`.
Plane refine(const Plane& plane, const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  int count = 0;
  for (const Eigen::Vector3d& p : points) {
    if (std::abs(plane.normal.dot(p) + plane.offset) > kInlierDistance) continue;
    centroid += p;
    scatter += p * p.transpose();
    ++count;
  }
  centroid /= count;
  scatter = scatter / count - centroid * centroid.transpose();
  Eigen::Vector3d normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
  if (normal.z() < 0.0) normal = -normal;
  return {normal, -normal.dot(centroid)};
}

}  // namespace

std::optional<double> groundHeightBelow(const PointCloud& cloud, size_t stride) {
  const std::vector<Eigen::Vector3d> points = pointsBelow(cloud, stride);
  if (points.size() < kMinPoints) return std::nullopt;
  // RANSAC with a fixed sequence of samples: the same scan always gives the same height.
  uint64_t state = 0x9E3779B97F4A7C15ull;
  const auto pick = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return points[(state >> 33) % points.size()];
  };
  std::optional<Plane> best;
  size_t best_inliers = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const std::optional<Plane> plane = planeThrough(pick(), pick(), pick());
    if (!plane) continue;
    const size_t inliers = std::count_if(points.begin(), points.end(), [&](const Eigen::Vector3d& p) {
      return std::abs(plane->normal.dot(p) + plane->offset) <= kInlierDistance;
    });
    if (inliers > best_inliers) {
      best = plane;
      best_inliers = inliers;
    }
  }
  if (!best || best_inliers < kMinInlierShare * points.size()) return std::nullopt;
  return refine(*best, points).offset;
}

std::optional<double> SensorHeightCheck::measured() const {
  if (recent_.empty()) return std::nullopt;
  return upperMedian(std::vector<double>(recent_.begin(), recent_.end()));
}

std::string SensorHeightCheck::add(const PointCloud& cloud) {
  constexpr size_t kStride = 16;  // about 8000 points of an HDL-64E scan, 1800 of a VLP-16's
  const std::optional<double> height = groundHeightBelow(cloud, kStride);
  if (!height) return {};
  recent_.push_back(*height);
  if (recent_.size() > kRecentScans) recent_.pop_front();
  if (recent_.size() < kRecentScans) return {};
  const double median = *measured();
  const bool off = std::abs(median - configured_) > kSensorHeightTolerance;
  const bool newly_off = off && !warned_;
  warned_ = off;
  if (!newly_off) return {};
  char text[320];
  std::snprintf(text, sizeof(text),
                "the ground lies %.2f m below the sensor (median of the last %zu scans) but ground.sensor_height "
                "is %.2f: ground segmentation looks for the road in the wrong place; set ground.sensor_height=%.2f",
                median, kRecentScans, configured_, median);
  return text;
}

}  // namespace elo
