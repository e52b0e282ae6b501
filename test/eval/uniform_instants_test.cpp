#include "elo/eval/uniform_instants.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace elo {
namespace {

constexpr double kPeriod = 0.1035;  // KITTI-raw's HDL-64E
constexpr double kFirstInstant = 0.0031;

std::vector<double> trueInstants(size_t scans) {
  std::vector<double> instants;
  for (size_t i = 0; i < scans; ++i) instants.push_back(kFirstInstant + kPeriod * static_cast<double>(i));
  return instants;
}

// As KITTI-raw stamps them: the instants rounded to the 100 Hz OXTS sample nearest.
std::vector<double> roundedTo10Ms(const std::vector<double>& instants) {
  std::vector<double> stamps;
  for (double instant : instants) stamps.push_back(std::round(instant * 100.0) / 100.0);
  return stamps;
}

// A vehicle at 20 m/s along a fixed direction, turning about a fixed tilted axis at 10 deg/s: positions
// linear and rotations geodesic in time, so that interpolation between any two of its poses is exact.
Eigen::Isometry3d poseAt(double time) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                  Eigen::AngleAxisd(time * 10.0 * M_PI / 180.0, Eigen::Vector3d(0.1, -0.2, 1.0).normalized())
                      .toRotationMatrix();
  pose.translation() = Eigen::Vector3d(4.0, -2.0, 0.5) + time * Eigen::Vector3d(18.0, 8.0, 1.5).normalized() * 20.0;
  return pose;
}

std::vector<Eigen::Isometry3d> posesAt(const std::vector<double>& times) {
  std::vector<Eigen::Isometry3d> poses;
  for (double time : times) poses.push_back(poseAt(time));
  return poses;
}

double largestPositionGap(const std::vector<Eigen::Isometry3d>& a, const std::vector<Eigen::Isometry3d>& b) {
  double largest = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    largest = std::max(largest, (a[i].translation() - b[i].translation()).norm());
  }
  return largest;
}

TEST(UniformInstants, StampsOnALineAreTheirOwnInstants) {
  const std::vector<double> instants = trueInstants(50);
  const UniformInstants fit = fitUniformInstants(instants);
  EXPECT_NEAR(fit.period_s, kPeriod, 1e-12);
  EXPECT_NEAR(fit.largest_offset_s, 0.0, 1e-12);
  for (size_t i = 0; i < instants.size(); ++i) EXPECT_NEAR(fit.instants[i], instants[i], 1e-12);
}

TEST(UniformInstants, StampsRoundedTo10MsGiveBackTheSensorsInstants) {
  const std::vector<double> instants = trueInstants(150);
  const UniformInstants fit = fitUniformInstants(roundedTo10Ms(instants));
  // The stamps step by 0.10 or 0.11 s; the line through them finds the period and the instants to well
  // under the 5 ms the rounding moved each stamp.
  EXPECT_NEAR(fit.period_s, kPeriod, 2e-5);
  EXPECT_GT(fit.largest_offset_s, 0.004);
  EXPECT_LE(fit.largest_offset_s, 0.0055);
  for (size_t i = 0; i < instants.size(); ++i) EXPECT_NEAR(fit.instants[i], instants[i], 1e-3) << "scan " << i;
}

TEST(UniformInstants, PosesAtTheStampsInterpolateExactlyToTheInstants) {
  const std::vector<double> instants = trueInstants(40);
  const std::vector<double> stamps = roundedTo10Ms(instants);
  const std::vector<Eigen::Isometry3d> sampled = posesAt(stamps);
  const std::vector<Eigen::Isometry3d> truth = posesAt(instants);
  // The stamps' poses are up to 5 ms of travel at 20 m/s, 0.1 m, off the scans'.
  EXPECT_GT(largestPositionGap(sampled, truth), 0.08);
  const std::vector<Eigen::Isometry3d> interpolated = interpolatePoses(sampled, stamps, instants);
  ASSERT_EQ(interpolated.size(), instants.size());
  for (size_t i = 0; i < instants.size(); ++i) {
    EXPECT_LT((interpolated[i].matrix() - truth[i].matrix()).cwiseAbs().maxCoeff(), 1e-9) << "scan " << i;
  }
}

TEST(UniformInstants, InstantsBeyondTheStampsAreExtrapolated) {
  const std::vector<double> stamps = {1.0, 1.1, 1.2};
  const std::vector<double> instants = {0.95, 1.05, 1.26};
  const std::vector<Eigen::Isometry3d> extrapolated = interpolatePoses(posesAt(stamps), stamps, instants);
  for (size_t i = 0; i < instants.size(); ++i) {
    EXPECT_LT((extrapolated[i].matrix() - poseAt(instants[i]).matrix()).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(UniformInstants, StampsOfNoSteadyRateAreRefused) {
  EXPECT_THROW(fitUniformInstants({0.0}), std::invalid_argument);
  EXPECT_THROW(fitUniformInstants({0.0, 0.1, 0.1, 0.3}), std::invalid_argument);  // one stamp twice
  EXPECT_THROW(fitUniformInstants({0.0, 0.2, 0.1, 0.3}), std::invalid_argument);  // going backwards
  // Five scans missing in the middle of twenty: no line holds every stamp within half a period.
  std::vector<double> with_gap = trueInstants(25);
  with_gap.erase(with_gap.begin() + 10, with_gap.begin() + 15);
  EXPECT_THROW(fitUniformInstants(with_gap), std::invalid_argument);
}

TEST(UniformInstants, PosesAndStampsMustPair) {
  const std::vector<double> stamps = {0.0, 0.1, 0.2};
  EXPECT_THROW(interpolatePoses(posesAt({0.0, 0.1}), stamps, stamps), std::invalid_argument);
  EXPECT_THROW(interpolatePoses(posesAt({0.0}), {0.0}, {0.0}), std::invalid_argument);
}

}  // namespace
}  // namespace elo
