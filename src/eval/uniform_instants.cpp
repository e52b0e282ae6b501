#include "elo/eval/uniform_instants.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace elo {

UniformInstants fitUniformInstants(const std::vector<double>& stamps) {
  if (stamps.size() < 2) throw std::invalid_argument("at least two stamps are needed to fit their period");
  for (size_t i = 1; i < stamps.size(); ++i) {
    if (!(stamps[i] > stamps[i - 1])) {
      throw std::invalid_argument("stamp " + std::to_string(i) + " does not follow stamp " + std::to_string(i - 1));
    }
  }
  const double count = static_cast<double>(stamps.size());
  const double mean_index = (count - 1.0) / 2.0;
  double mean_stamp = 0.0;
  for (double stamp : stamps) mean_stamp += stamp / count;
  double covariance = 0.0;
  double index_variance = 0.0;
  for (size_t i = 0; i < stamps.size(); ++i) {
    const double index_offset = static_cast<double>(i) - mean_index;
    covariance += index_offset * (stamps[i] - mean_stamp);
    index_variance += index_offset * index_offset;
  }
  UniformInstants fit;
  fit.period_s = covariance / index_variance;
  for (size_t i = 0; i < stamps.size(); ++i) {
    fit.instants.push_back(mean_stamp + (static_cast<double>(i) - mean_index) * fit.period_s);
    fit.largest_offset_s = std::max(fit.largest_offset_s, std::abs(stamps[i] - fit.instants.back()));
  }
  if (fit.largest_offset_s > fit.period_s / 2.0) {
    throw std::invalid_argument("the stamps are not a steady rate: one lies " +
                                std::to_string(fit.largest_offset_s) + " s off the line of period " +
                                std::to_string(fit.period_s) + " s fitted to them");
  }
  return fit;
}

namespace {

// The pose a fraction `s` of the way from `from` to `to` (s outside [0, 1] extrapolates).
Eigen::Isometry3d poseBetween(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double s) {
  const Eigen::AngleAxisd step(from.linear().transpose() * to.linear());
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = from.linear() * Eigen::AngleAxisd(s * step.angle(), step.axis()).toRotationMatrix();
  pose.translation() = (1.0 - s) * from.translation() + s * to.translation();
  return pose;
}

}  // namespace

std::vector<Eigen::Isometry3d> interpolatePoses(const std::vector<Eigen::Isometry3d>& poses,
                                                const std::vector<double>& stamps,
                                                const std::vector<double>& instants) {
  if (poses.size() != stamps.size()) {
    throw std::invalid_argument(std::to_string(poses.size()) + " poses for " + std::to_string(stamps.size()) +
                                " stamps");
  }
  if (poses.size() < 2) throw std::invalid_argument("at least two poses are needed to interpolate between");
  std::vector<Eigen::Isometry3d> interpolated;
  interpolated.reserve(instants.size());
  for (double instant : instants) {
    // The pair of stamps around the instant, or the first or last pair for one beyond them.
    const auto after = std::upper_bound(stamps.begin() + 1, stamps.end() - 1, instant);
    const size_t i = static_cast<size_t>(after - stamps.begin()) - 1;
    const double s = (instant - stamps[i]) / (stamps[i + 1] - stamps[i]);
    interpolated.push_back(poseBetween(poses[i], poses[i + 1], s));
  }
  return interpolated;
}

}  // namespace elo
