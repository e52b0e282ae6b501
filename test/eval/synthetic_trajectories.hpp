// Trajectories with known errors for the metric tests.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

namespace elo::test {

inline Eigen::Isometry3d yaw(double angle) {
  return Eigen::Isometry3d(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()));
}

inline Eigen::Isometry3d translation(const Eigen::Vector3d& offset) {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.translation() = offset;
  return transform;
}

// Poses that chain the same body-frame motion `step` from the identity.
inline std::vector<Eigen::Isometry3d> chain(const Eigen::Isometry3d& step, size_t frames) {
  std::vector<Eigen::Isometry3d> poses{Eigen::Isometry3d::Identity()};
  while (poses.size() < frames) poses.push_back(poses.back() * step);
  return poses;
}

// Straight along a tilted heading, `spacing` metres a frame.
inline std::vector<Eigen::Isometry3d> straightLine(size_t frames, double spacing) {
  const Eigen::Isometry3d heading(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()));
  std::vector<Eigen::Isometry3d> poses = chain(translation(Eigen::Vector3d(spacing, 0, 0)), frames);
  for (Eigen::Isometry3d& pose : poses) pose = heading * pose * heading.inverse();
  return poses;
}

// A circle in closed form (chaining would let rounding drift): frames `spacing` apart along the
// circle's chords, each turned by a further `turn` rad about z; a straight line along x for turn 0.
inline std::vector<Eigen::Isometry3d> circle(size_t frames, double spacing, double turn) {
  const double radius = turn == 0.0 ? 0.0 : spacing / (2.0 * std::sin(turn / 2.0));
  std::vector<Eigen::Isometry3d> poses;
  for (size_t i = 0; i < frames; ++i) {
    const double heading = turn * static_cast<double>(i);
    const Eigen::Vector3d position = turn == 0.0 ? Eigen::Vector3d(spacing * static_cast<double>(i), 0, 0)
                                                 : Eigen::Vector3d(radius * std::sin(heading),
                                                                   radius * (1.0 - std::cos(heading)), 0);
    poses.push_back(translation(position) * yaw(heading));
  }
  return poses;
}

// The estimate of an odometry that overestimates every translation increment by `scale`. Chaining
// est_i = est_i-1 * [dR, scale * dt] keeps the rotations and moves every position to
// p_0 + scale * (p_i - p_0); this writes that directly, so the rotations stay exactly the truth's
// (rounding in chained rotations would show up as rotation error).
inline std::vector<Eigen::Isometry3d> scaleIncrements(const std::vector<Eigen::Isometry3d>& poses, double scale) {
  std::vector<Eigen::Isometry3d> scaled = poses;
  for (Eigen::Isometry3d& pose : scaled) {
    pose.translation() = poses.front().translation() + scale * (pose.translation() - poses.front().translation());
  }
  return scaled;
}

}  // namespace elo::test
