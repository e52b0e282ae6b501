#include "worlds/shapes.hpp"

#include <algorithm>
#include <cmath>

namespace elo::sim {
namespace {

constexpr float kFoliageReflectivity = 0.35f;
constexpr float kBarkReflectivity = 0.25f;
constexpr double kEmbedding = 0.2;  // m a trunk reaches below the ground, so that slopes leave no gap

// A lobe of leaves: an ellipsoid that beams may reach into before they echo.
Primitive foliage(const Ellipsoid& lobe) {
  Primitive leaves(lobe, kFoliageReflectivity);
  leaves.foliage = true;
  return leaves;
}

}  // namespace

CarBody CarBody::random(Rng& rng) {
  CarBody body;
  body.length = rng.uniform(3.9, 4.9);
  body.width = rng.uniform(1.7, 1.9);
  body.cabin_height = rng.uniform(0.45, 0.7);
  body.reflectivity = static_cast<float>(rng.uniform(0.1, 0.9));
  return body;
}

void addCar(std::vector<Primitive>& out, const Eigen::Vector2d& position, double heading, double ground_z,
            const CarBody& body) {
  constexpr double kClearance = 0.3;    // m under the body
  constexpr double kBodyHeight = 0.75;  // m from the sills to the window line
  const Eigen::Vector2d forward(std::cos(heading), std::sin(heading));
  const double body_center_z = ground_z + kClearance + 0.5 * kBodyHeight;
  out.push_back({uprightBox(Eigen::Vector3d(position.x(), position.y(), body_center_z),
                            Eigen::Vector3d(body.length, body.width, kBodyHeight), heading),
                 body.reflectivity});
  // The cabin sits a little behind the middle, narrower than the body.
  const Eigen::Vector2d cabin_xy = position - 0.1 * body.length * forward;
  const double cabin_center_z = ground_z + kClearance + kBodyHeight + 0.5 * body.cabin_height;
  out.push_back({uprightBox(Eigen::Vector3d(cabin_xy.x(), cabin_xy.y(), cabin_center_z),
                            Eigen::Vector3d(0.5 * body.length, 0.88 * body.width, body.cabin_height), heading),
                 0.5f * body.reflectivity});  // glass returns weaker echoes than paint
}

WindowGrid randomWindows(Rng& rng) {
  WindowGrid windows;
  windows.storey_height = rng.uniform(3.0, 3.6);
  windows.sill_height = rng.uniform(0.8, 1.0);
  windows.window_height = rng.uniform(1.2, 1.8);
  windows.spacing = rng.uniform(2.5, 4.0);
  windows.window_width = rng.uniform(0.35, 0.6) * windows.spacing;
  return windows;
}

void addTree(std::vector<Primitive>& out, const Eigen::Vector2d& position, double ground_z, Rng& rng) {
  const double trunk_radius = rng.uniform(0.12, 0.3);
  const double trunk_height = rng.uniform(1.8, 3.5);
  out.push_back({VerticalCylinder{position, trunk_radius, ground_z - kEmbedding, ground_z + trunk_height + 0.5},
                 kBarkReflectivity});
  const double crown = rng.uniform(1.2, 3.0);
  const Eigen::Vector3d crown_center(position.x(), position.y(), ground_z + trunk_height + crown);
  const int lobes = rng.uniformInt(3, 6);
  for (int lobe = 0; lobe < lobes; ++lobe) {
    const Eigen::Vector3d offset(rng.uniform(-0.5, 0.5) * crown, rng.uniform(-0.5, 0.5) * crown,
                                 rng.uniform(-0.3, 0.4) * crown);
    const Eigen::Vector3d radii(rng.uniform(0.6, 1.0) * crown, rng.uniform(0.6, 1.0) * crown,
                                rng.uniform(0.5, 0.9) * crown);
    out.push_back(foliage(Ellipsoid{crown_center + offset, radii, rng.uniform(0.0, M_PI)}));
  }
}

void addBush(std::vector<Primitive>& out, const Eigen::Vector2d& position, double ground_z, Rng& rng) {
  const int lobes = rng.uniformInt(2, 4);
  const double size = rng.uniform(0.5, 1.4);
  for (int lobe = 0; lobe < lobes; ++lobe) {
    const Eigen::Vector3d center(position.x() + rng.uniform(-0.7, 0.7) * size,
                                 position.y() + rng.uniform(-0.7, 0.7) * size, ground_z + rng.uniform(0.1, 0.5) * size);
    const Eigen::Vector3d radii(rng.uniform(0.6, 1.0) * size, rng.uniform(0.6, 1.0) * size,
                                rng.uniform(0.5, 0.9) * size);
    out.push_back(foliage(Ellipsoid{center, radii, rng.uniform(0.0, M_PI)}));
  }
}

}  // namespace elo::sim
