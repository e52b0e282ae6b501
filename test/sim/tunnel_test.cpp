// The tunnel world: an open approach, then a tube whose road, walls and ceiling do not change along it,
// so that nothing in it tells a LiDAR how far it has driven (the degenerate case of odometry).
#include <gtest/gtest.h>

#include <cmath>

#include "elo/sim/simulation.hpp"

namespace elo::sim {
namespace {

constexpr double kSensorHeight = 1.73;

// What a sensor standing on the road `distance` metres along a straight route along +x sees along
// `direction`: the range of the first hit, or -1 for none within 200 m.
double rangeSeen(const World& world, double distance, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d origin(distance, 0.0, world.ground().height(distance, 0.0) + kSensorHeight);
  const std::optional<Hit> hit = world.scene().cast(Ray{origin, direction.normalized()}, 200.0);
  return hit ? hit->distance : -1.0;
}

TEST(TunnelWorld, IsOpenBeforeThePortalAndAnUnchangingTubeAfterIt) {
  const Route route = proceduralRoute(TrajectoryKind::straight, cruiseSpeed(WorldFamily::tunnel), 45.0);
  const World world(WorldFamily::tunnel, route, WorldOptions{});
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  EXPECT_LT(rangeSeen(world, 40.0, up), 0.0) << "the approach is open to the sky";

  // Inside, beams in every direction but straight along the axis meet the same surfaces at the same
  // ranges wherever the sensor stands (positions apart by no multiple of the 6 m wall segments).
  const std::vector<Eigen::Vector3d> directions = {
      up, Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitY(), {0.3, 1.0, 0.2}, {-0.5, -1.0, 0.4},
      {1.0, 0.2, -0.15}, {-1.0, 0.1, 0.05}, {2.0, -0.3, 0.1}};
  const std::vector<double> positions = {160.0, 243.7, 391.1, 520.4};
  for (const Eigen::Vector3d& direction : directions) {
    const double reference = rangeSeen(world, positions[0], direction);
    ASSERT_GT(reference, 0.0) << direction.transpose();
    for (const double position : positions) {
      EXPECT_NEAR(rangeSeen(world, position, direction), reference, 1e-6)
          << "at " << position << " m along " << direction.transpose();
    }
  }
  // Walls 5.5 m to either side, the ceiling 5.2 m above the road (minus the crown).
  EXPECT_NEAR(rangeSeen(world, 300.0, Eigen::Vector3d::UnitY()), 5.5, 1e-6);
  EXPECT_NEAR(rangeSeen(world, 300.0, up), 5.2 - 0.015 * 3.0 - kSensorHeight, 0.01);
}

TEST(TunnelWorld, SameSeedSameScans) {
  SimulationSpec spec;
  spec.world = WorldFamily::tunnel;
  spec.trajectory = TrajectoryKind::straight;
  spec.frames = 2;
  spec.seed = 4;
  const SimulatedScan a = Simulation(spec).scan(1);
  const SimulatedScan b = Simulation(spec).scan(1);
  spec.seed = 5;
  const SimulatedScan c = Simulation(spec).scan(1);
  ASSERT_EQ(a.cloud.size(), b.cloud.size());
  EXPECT_TRUE(a.cloud.points == b.cloud.points);
  EXPECT_FALSE(a.cloud.size() == c.cloud.size() && a.cloud.points == c.cloud.points);
}

}  // namespace
}  // namespace elo::sim
