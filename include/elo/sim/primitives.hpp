// The analytic shapes worlds are built of, and exact ray intersection with each. Distances are along
// a unit direction, in double precision, so that a test can compare a simulated range with the
// closed-form answer.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <variant>

namespace elo::sim {

struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;  // unit length
  Eigen::Vector3d at(double distance) const { return origin + distance * direction; }
};

struct SurfaceHit {
  double distance = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, on the side the ray came from
};

// A box of any orientation: `axes` holds the box's x, y and z axes as columns (a rotation).
struct OrientedBox {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d half_extents = Eigen::Vector3d::Ones();
};

// Poles, trunks, bollards: an upright cylinder with flat caps.
struct VerticalCylinder {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double radius = 0.1;
  double z_min = 0.0;
  double z_max = 1.0;
};

// Canopies and bushes (several overlapping ellipsoids make an irregular blob); turned by `yaw` about z.
struct Ellipsoid {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();
  double yaw = 0.0;
};

using Shape = std::variant<OrientedBox, VerticalCylinder, Ellipsoid>;

// Rows of windows on the upright faces of a box, one row a storey. Glass mirrors the beam away, so
// a window returns no echo and the facade shows holes, as in real scans.
struct WindowGrid {
  double storey_height = 3.2;   // m
  double sill_height = 0.9;     // m from a storey's floor to its windows' bottom
  double window_height = 1.5;   // m
  double spacing = 3.0;         // m between window centres along the face
  double window_width = 1.5;    // m
};

struct Primitive {
  Primitive(Shape shape_, float reflectivity_, std::optional<WindowGrid> windows_ = std::nullopt)
      : shape(std::move(shape_)), reflectivity(reflectivity_), windows(windows_) {}

  Shape shape;
  float reflectivity;                 // 0..1: the intensity of a return at normal incidence
  std::optional<WindowGrid> windows;  // boxes only
  bool foliage = false;               // leaves: beams may reach into it before echoing (LidarOptions)
};

// The reflectivity a beam meets where it hits `point` (with surface `normal`) of the primitive: its
// own, or zero on window glass.
float reflectivityAt(const Primitive& primitive, const Eigen::Vector3d& point, const Eigen::Vector3d& normal);

struct Bounds3 {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
};

// The first entry of the ray into the shape with distance in [min_distance, max_distance]; a ray that
// starts inside a shape does not hit it (the sensor is never inside an object).
std::optional<SurfaceHit> intersect(const Ray& ray, const OrientedBox& box, double min_distance, double max_distance);
std::optional<SurfaceHit> intersect(const Ray& ray, const VerticalCylinder& cylinder, double min_distance,
                                    double max_distance);
std::optional<SurfaceHit> intersect(const Ray& ray, const Ellipsoid& ellipsoid, double min_distance,
                                    double max_distance);
std::optional<SurfaceHit> intersect(const Ray& ray, const Shape& shape, double min_distance, double max_distance);

// Axis-aligned bounds, for the grid that finds a ray's candidate shapes.
Bounds3 bounds(const OrientedBox& box);
Bounds3 bounds(const VerticalCylinder& cylinder);
Bounds3 bounds(const Ellipsoid& ellipsoid);
Bounds3 bounds(const Shape& shape);

// A box standing upright, turned by `yaw` about z: the common case (buildings, cars, rails).
OrientedBox uprightBox(const Eigen::Vector3d& center, const Eigen::Vector3d& size, double yaw);

}  // namespace elo::sim
