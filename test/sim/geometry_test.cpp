// Exact ray intersection with each primitive and with the ground, and the grid search against brute force.
#include <gtest/gtest.h>

#include <cmath>

#include "elo/sim/ground.hpp"
#include "elo/sim/primitives.hpp"
#include "elo/sim/rng.hpp"
#include "elo/sim/scene.hpp"

namespace elo::sim {
namespace {

Ray rayFrom(const Eigen::Vector3d& origin, double azimuth, double elevation) {
  return {origin, Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                  std::sin(elevation))};
}

TEST(Rng, SameSeedSameNumbersAndSaneMoments) {
  Rng a(42), b(42), c(43);
  double sum = 0.0, sum_squares = 0.0, gaussian_sum = 0.0, gaussian_squares = 0.0;
  constexpr int kDraws = 200000;
  bool differs_from_other_seed = false;
  for (int i = 0; i < kDraws; ++i) {
    const double u = a.uniform();
    ASSERT_EQ(u, b.uniform());
    differs_from_other_seed |= u != c.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum_squares += u * u;
    const double g = a.gaussian();
    ASSERT_EQ(g, b.gaussian());
    c.gaussian();
    gaussian_sum += g;
    gaussian_squares += g * g;
  }
  EXPECT_TRUE(differs_from_other_seed);
  EXPECT_NEAR(sum / kDraws, 0.5, 0.005);
  EXPECT_NEAR(sum_squares / kDraws - 0.25, 1.0 / 12.0, 0.002);
  EXPECT_NEAR(gaussian_sum / kDraws, 0.0, 0.01);
  EXPECT_NEAR(gaussian_squares / kDraws, 1.0, 0.01);
  for (int i = 0; i < 1000; ++i) {
    const int k = a.uniformInt(3, 5);
    ASSERT_TRUE(k >= 3 && k <= 5);
  }
  EXPECT_NE(mixSeed(1, 2), mixSeed(1, 3));
  EXPECT_NE(mixSeed(1, 2, 0), mixSeed(2, 1, 0));
}

TEST(Primitives, AxisAlignedBoxFaceDistance) {
  const OrientedBox box{Eigen::Vector3d(5.0, 0.0, 0.0), Eigen::Matrix3d::Identity(), Eigen::Vector3d(1.0, 2.0, 3.0)};
  for (const double azimuth : {0.0, 0.2, -0.3}) {
    for (const double elevation : {0.0, 0.25, -0.4}) {
      const Ray ray = rayFrom(Eigen::Vector3d::Zero(), azimuth, elevation);
      const auto hit = intersect(ray, box, 0.0, 100.0);
      ASSERT_TRUE(hit);
      EXPECT_NEAR(hit->distance, 4.0 / (std::cos(elevation) * std::cos(azimuth)), 1e-12);
      EXPECT_NEAR(hit->normal.x(), -1.0, 1e-12);
    }
  }
  EXPECT_FALSE(intersect(rayFrom(Eigen::Vector3d::Zero(), M_PI, 0.0), box, 0.0, 100.0));  // behind
  EXPECT_FALSE(intersect(rayFrom(Eigen::Vector3d::Zero(), 0.0, 0.0), box, 0.0, 3.9));     // too far
  EXPECT_FALSE(intersect(rayFrom(Eigen::Vector3d(5.0, 0.0, 0.0), 0.0, 0.0), box, 0.0, 100.0));  // inside
}

TEST(Primitives, RotatedBoxAlongItsAxis) {
  const double yaw = 0.5;
  const OrientedBox box = uprightBox(Eigen::Vector3d(10.0 * std::cos(yaw), 10.0 * std::sin(yaw), 1.0),
                                     Eigen::Vector3d(4.0, 1.0, 2.0), yaw);
  const auto hit = intersect(rayFrom(Eigen::Vector3d(0.0, 0.0, 1.0), yaw, 0.0), box, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->distance, 8.0, 1e-12);
  EXPECT_NEAR(hit->normal.x(), -std::cos(yaw), 1e-12);
  EXPECT_NEAR(hit->normal.y(), -std::sin(yaw), 1e-12);
}

TEST(Primitives, CylinderSideAndCap) {
  const VerticalCylinder pole{Eigen::Vector2d(10.0, 0.0), 0.5, -2.0, 3.0};
  for (const double azimuth : {0.0, 0.03, -0.04}) {
    for (const double elevation : {0.0, 0.2, -0.15}) {
      const auto hit = intersect(rayFrom(Eigen::Vector3d::Zero(), azimuth, elevation), pole, 0.0, 100.0);
      ASSERT_TRUE(hit);
      // The horizontal distance to the circle, then along the slanted ray.
      const double across = 10.0 * std::sin(azimuth);
      const double horizontal = 10.0 * std::cos(azimuth) - std::sqrt(0.25 - across * across);
      EXPECT_NEAR(hit->distance, horizontal / std::cos(elevation), 1e-12);
      EXPECT_NEAR(hit->normal.z(), 0.0, 1e-12);
    }
  }
  // Straight down onto the top cap.
  const auto cap = intersect(Ray{Eigen::Vector3d(10.2, 0.1, 8.0), -Eigen::Vector3d::UnitZ()}, pole, 0.0, 100.0);
  ASSERT_TRUE(cap);
  EXPECT_NEAR(cap->distance, 5.0, 1e-12);
  EXPECT_NEAR(cap->normal.z(), 1.0, 1e-12);
  // Passing over the top.
  EXPECT_FALSE(intersect(rayFrom(Eigen::Vector3d(0.0, 0.0, 3.5), 0.0, 0.0), pole, 0.0, 100.0));
}

TEST(Primitives, EllipsoidAlongEachAxis) {
  const Ellipsoid blob{Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(1.0, 2.0, 3.0), 0.0};
  const auto along_x = intersect(Ray{Eigen::Vector3d(-10.0, 0.0, 0.0), Eigen::Vector3d::UnitX()}, blob, 0.0, 100.0);
  const auto along_y = intersect(Ray{Eigen::Vector3d(0.0, -10.0, 0.0), Eigen::Vector3d::UnitY()}, blob, 0.0, 100.0);
  const auto along_z = intersect(Ray{Eigen::Vector3d(0.0, 0.0, 10.0), -Eigen::Vector3d::UnitZ()}, blob, 0.0, 100.0);
  ASSERT_TRUE(along_x && along_y && along_z);
  EXPECT_NEAR(along_x->distance, 9.0, 1e-12);
  EXPECT_NEAR(along_y->distance, 8.0, 1e-12);
  EXPECT_NEAR(along_z->distance, 7.0, 1e-12);
  EXPECT_NEAR(along_z->normal.z(), 1.0, 1e-12);
  // Turned by 90 deg, the long horizontal axis lies along x.
  const Ellipsoid turned{Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 2.0, 3.0), M_PI / 2};
  const auto turned_x = intersect(Ray{Eigen::Vector3d(-10.0, 0.0, 0.0), Eigen::Vector3d::UnitX()}, turned, 0.0, 100.0);
  ASSERT_TRUE(turned_x);
  EXPECT_NEAR(turned_x->distance, 8.0, 1e-12);
}

TEST(Ground, FlatGroundClosedForm) {
  const FlatGround ground(-1.73);
  for (const double elevation : {-0.01, -0.1, -0.4}) {
    const auto distance = ground.intersect(rayFrom(Eigen::Vector3d::Zero(), 0.7, elevation), 0.0, 1000.0);
    ASSERT_TRUE(distance);
    EXPECT_NEAR(*distance, 1.73 / std::sin(-elevation), 1e-12);
  }
  EXPECT_FALSE(ground.intersect(rayFrom(Eigen::Vector3d::Zero(), 0.0, 0.1), 0.0, 1000.0));
}

TEST(Ground, HeightFieldIsExactOnPlanes) {
  // A sloped plane: bilinear interpolation reproduces it, and the root refinement finds it exactly.
  const auto plane = [](double x, double y) { return -1.7 + 0.05 * x - 0.02 * y; };
  const HeightField field(plane, {Eigen::Vector2d::Zero()}, 80.0);
  EXPECT_NEAR(field.height(3.33, -7.1), plane(3.33, -7.1), 1e-6);
  Rng rng(7);
  for (int i = 0; i < 2000; ++i) {
    const Ray ray = rayFrom(Eigen::Vector3d::Zero(), rng.uniform(-M_PI, M_PI), rng.uniform(-0.45, -0.02));
    const auto distance = field.intersect(ray, 0.0, 70.0);
    // Closed form: z0 + t dz = -1.7 + 0.05 t dx - 0.02 t dy.
    const double expected = -1.7 / (ray.direction.z() - 0.05 * ray.direction.x() + 0.02 * ray.direction.y());
    if (expected > 0.0 && expected < 70.0) {
      ASSERT_TRUE(distance) << "ray " << i;
      EXPECT_NEAR(*distance, expected, 1e-5 * expected);  // float samples: relative precision 1e-6
    } else {
      EXPECT_FALSE(distance);
    }
  }
}

TEST(Ground, HeightFieldHitsLieOnTheSurfaceAndAreTheFirstCrossing) {
  const auto hills = [](double x, double y) { return 2.0 * std::sin(0.05 * x) * std::cos(0.07 * y) + 0.05 * std::sin(1.3 * x); };
  const HeightField field(hills, {Eigen::Vector2d::Zero()}, 90.0);
  Rng rng(8);
  int hits = 0;
  for (int i = 0; i < 1000; ++i) {
    const Ray ray = rayFrom(Eigen::Vector3d(0.0, 0.0, 3.0), rng.uniform(-M_PI, M_PI), rng.uniform(-0.4, 0.05));
    const auto distance = field.intersect(ray, 0.0, 80.0);
    if (!distance) continue;
    ++hits;
    const Eigen::Vector3d point = ray.at(*distance);
    EXPECT_NEAR(point.z(), field.height(point.x(), point.y()), 1e-8);
    for (double t = 0.0; t < *distance - 0.01; t += 0.01) {
      const Eigen::Vector3d before = ray.at(t);
      ASSERT_GT(before.z(), field.height(before.x(), before.y())) << "crossing missed before " << *distance;
    }
  }
  EXPECT_GT(hits, 500);
}

TEST(Ground, HeightFieldFollowsItsSurfaceAndCoversOnlyTheReach) {
  const auto bumps = [](double x, double y) { return std::sin(x) + std::cos(0.5 * y); };
  const HeightField field(bumps, {Eigen::Vector2d(100.0, 0.0)}, 30.0, 0.1);
  EXPECT_NEAR(field.height(101.234, 5.678), bumps(101.234, 5.678), 0.01);
  EXPECT_EQ(field.height(0.0, 0.0), bumps(0.0, 0.0));  // outside the raster: the function itself
  // Rays far from the raster find no ground.
  EXPECT_FALSE(field.intersect(Ray{Eigen::Vector3d(0.0, 0.0, 5.0), -Eigen::Vector3d::UnitZ()}, 0.0, 100.0));
  EXPECT_TRUE(field.intersect(Ray{Eigen::Vector3d(100.0, 0.0, 5.0), -Eigen::Vector3d::UnitZ()}, 0.0, 100.0));
}

TEST(Scene, GridFindsTheSameHitsAsTestingEveryPrimitive) {
  Rng rng(3);
  std::vector<Primitive> primitives;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d center(rng.uniform(-60.0, 60.0), rng.uniform(-60.0, 60.0), rng.uniform(-1.0, 4.0));
    switch (i % 3) {
      case 0:
        primitives.push_back({uprightBox(center, Eigen::Vector3d(rng.uniform(0.2, 12.0), rng.uniform(0.2, 6.0),
                                                                 rng.uniform(0.5, 10.0)),
                                         rng.uniform(0.0, M_PI)),
                              0.5f});
        break;
      case 1:
        primitives.push_back({VerticalCylinder{center.head<2>(), rng.uniform(0.05, 1.0), center.z() - 2.0, center.z() + 3.0}, 0.5f});
        break;
      default:
        primitives.push_back({Ellipsoid{center, Eigen::Vector3d(rng.uniform(0.3, 3.0), rng.uniform(0.3, 3.0), rng.uniform(0.3, 3.0)),
                                        rng.uniform(0.0, M_PI)},
                              0.5f});
    }
  }
  const Scene scene(nullptr, primitives, 0.15f, 4.0);
  int hits = 0;
  for (int i = 0; i < 5000; ++i) {
    const Ray ray = rayFrom(Eigen::Vector3d(rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0), 1.7),
                            rng.uniform(-M_PI, M_PI), rng.uniform(-0.3, 0.3));
    const auto gridded = scene.cast(ray, 100.0);
    const auto brute = castEach(ray, primitives, 100.0, SurfaceKind::object);
    ASSERT_EQ(gridded.has_value(), brute.has_value()) << "ray " << i;
    if (gridded) {
      ++hits;
      EXPECT_EQ(gridded->distance, brute->distance);
    }
  }
  EXPECT_GT(hits, 1000);
}

TEST(Scene, NearestOfGroundAndObjects) {
  const auto ground = std::make_shared<FlatGround>(-1.73);
  const Scene scene(ground, {{uprightBox(Eigen::Vector3d(10.0, 0.0, 0.0), Eigen::Vector3d(1.0, 1.0, 4.0), 0.0), 0.8f}});
  const auto wall = scene.cast(rayFrom(Eigen::Vector3d::Zero(), 0.0, -0.05), 100.0);
  ASSERT_TRUE(wall);
  EXPECT_EQ(wall->kind, SurfaceKind::object);
  EXPECT_FLOAT_EQ(wall->reflectivity, 0.8f);
  const auto road = scene.cast(rayFrom(Eigen::Vector3d::Zero(), 0.0, -0.3), 100.0);
  ASSERT_TRUE(road);
  EXPECT_EQ(road->kind, SurfaceKind::ground);
  EXPECT_NEAR(road->distance, 1.73 / std::sin(0.3), 1e-12);
}

}  // namespace
}  // namespace elo::sim
