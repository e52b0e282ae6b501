#include "elo/sim/primitives.hpp"

#include <cmath>
#include <limits>

namespace elo::sim {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

bool inRange(double distance, double min_distance, double max_distance) {
  return distance >= min_distance && distance <= max_distance;
}

// The smaller root of a*t^2 + 2*b*t + c = 0 (the entry point of a ray into a quadric), if real.
std::optional<double> nearRoot(double a, double b, double c) {
  const double discriminant = b * b - a * c;
  if (a <= 0.0 || discriminant < 0.0) return std::nullopt;
  return (-b - std::sqrt(discriminant)) / a;
}

Eigen::Matrix3d yawRotation(double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

std::optional<SurfaceHit> intersect(const Ray& ray, const OrientedBox& box, double min_distance,
                                    double max_distance) {
  // Slab test in the box frame, where the box is [-e, e] on every axis.
  const Eigen::Vector3d origin = box.axes.transpose() * (ray.origin - box.center);
  const Eigen::Vector3d direction = box.axes.transpose() * ray.direction;
  double entry = -kInfinity;
  double exit = kInfinity;
  int entry_axis = -1;
  for (int axis = 0; axis < 3; ++axis) {
    const double extent = box.half_extents[axis];
    if (direction[axis] == 0.0) {
      if (std::abs(origin[axis]) > extent) return std::nullopt;
      continue;
    }
    double near = (-extent - origin[axis]) / direction[axis];
    double far = (extent - origin[axis]) / direction[axis];
    if (near > far) std::swap(near, far);
    if (near > entry) {
      entry = near;
      entry_axis = axis;
    }
    exit = std::min(exit, far);
  }
  if (entry_axis < 0 || entry > exit || !inRange(entry, min_distance, max_distance) || entry < 0.0) {
    return std::nullopt;
  }
  const double side = direction[entry_axis] > 0.0 ? -1.0 : 1.0;
  return SurfaceHit{entry, side * box.axes.col(entry_axis)};
}

std::optional<SurfaceHit> intersect(const Ray& ray, const VerticalCylinder& cylinder, double min_distance,
                                    double max_distance) {
  std::optional<SurfaceHit> best;
  const auto keep = [&](double distance, const Eigen::Vector3d& normal) {
    if (inRange(distance, min_distance, max_distance) && (!best || distance < best->distance)) {
      best = SurfaceHit{distance, normal};
    }
  };
  const Eigen::Vector2d offset = ray.origin.head<2>() - cylinder.center;
  const Eigen::Vector2d planar = ray.direction.head<2>();
  const bool outside_side = offset.squaredNorm() > cylinder.radius * cylinder.radius;
  if (outside_side) {
    const auto side = nearRoot(planar.squaredNorm(), offset.dot(planar),
                               offset.squaredNorm() - cylinder.radius * cylinder.radius);
    if (side) {
      const Eigen::Vector3d point = ray.at(*side);
      if (point.z() >= cylinder.z_min && point.z() <= cylinder.z_max) {
        const Eigen::Vector2d radial = (point.head<2>() - cylinder.center) / cylinder.radius;
        keep(*side, Eigen::Vector3d(radial.x(), radial.y(), 0.0));
      }
    }
  }
  // Caps: only the one facing the ray origin can be its entry.
  const double cap_z = ray.origin.z() > cylinder.z_max ? cylinder.z_max
                       : ray.origin.z() < cylinder.z_min ? cylinder.z_min
                                                         : std::numeric_limits<double>::quiet_NaN();
  if (!std::isnan(cap_z) && ray.direction.z() != 0.0) {
    const double distance = (cap_z - ray.origin.z()) / ray.direction.z();
    const Eigen::Vector3d point = ray.at(distance);
    if ((point.head<2>() - cylinder.center).squaredNorm() <= cylinder.radius * cylinder.radius) {
      keep(distance, Eigen::Vector3d(0.0, 0.0, cap_z == cylinder.z_max ? 1.0 : -1.0));
    }
  }
  return best;
}

std::optional<SurfaceHit> intersect(const Ray& ray, const Ellipsoid& ellipsoid, double min_distance,
                                    double max_distance) {
  // In the frame where the ellipsoid is the unit sphere, the ray's parameter is still the world distance.
  const Eigen::Matrix3d to_local = yawRotation(-ellipsoid.yaw);
  const Eigen::Vector3d origin = (to_local * (ray.origin - ellipsoid.center)).cwiseQuotient(ellipsoid.radii);
  const Eigen::Vector3d direction = (to_local * ray.direction).cwiseQuotient(ellipsoid.radii);
  if (origin.squaredNorm() <= 1.0) return std::nullopt;
  const auto distance = nearRoot(direction.squaredNorm(), origin.dot(direction), origin.squaredNorm() - 1.0);
  if (!distance || !inRange(*distance, min_distance, max_distance)) return std::nullopt;
  // The gradient of |p / r|^2 is p / r^2, so the normal is the sphere point divided by r once more.
  const Eigen::Vector3d sphere_point = origin + *distance * direction;
  const Eigen::Vector3d local_normal = sphere_point.cwiseQuotient(ellipsoid.radii);
  return SurfaceHit{*distance, (yawRotation(ellipsoid.yaw) * local_normal).normalized()};
}

std::optional<SurfaceHit> intersect(const Ray& ray, const Shape& shape, double min_distance, double max_distance) {
  return std::visit([&](const auto& concrete) { return intersect(ray, concrete, min_distance, max_distance); },
                    shape);
}

Bounds3 bounds(const OrientedBox& box) {
  const Eigen::Vector3d reach = box.axes.cwiseAbs() * box.half_extents;
  return {box.center - reach, box.center + reach};
}

Bounds3 bounds(const VerticalCylinder& cylinder) {
  return {Eigen::Vector3d(cylinder.center.x() - cylinder.radius, cylinder.center.y() - cylinder.radius, cylinder.z_min),
          Eigen::Vector3d(cylinder.center.x() + cylinder.radius, cylinder.center.y() + cylinder.radius, cylinder.z_max)};
}

Bounds3 bounds(const Ellipsoid& ellipsoid) {
  const double c = std::cos(ellipsoid.yaw);
  const double s = std::sin(ellipsoid.yaw);
  const double rx = ellipsoid.radii.x();
  const double ry = ellipsoid.radii.y();
  const Eigen::Vector3d reach(std::hypot(rx * c, ry * s), std::hypot(rx * s, ry * c), ellipsoid.radii.z());
  return {ellipsoid.center - reach, ellipsoid.center + reach};
}

Bounds3 bounds(const Shape& shape) {
  return std::visit([](const auto& concrete) { return bounds(concrete); }, shape);
}

float reflectivityAt(const Primitive& primitive, const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  const auto* box = std::get_if<OrientedBox>(&primitive.shape);
  if (!primitive.windows || !box || std::abs(normal.z()) > 0.5) return primitive.reflectivity;
  const WindowGrid& grid = *primitive.windows;
  // Position on the face: along it from its left edge, and up from the box's bottom.
  const Eigen::Vector3d local = box->axes.transpose() * (point - box->center);
  const int across_axis = std::abs(normal.dot(box->axes.col(0))) > std::abs(normal.dot(box->axes.col(1))) ? 1 : 0;
  const double along = local[across_axis] + box->half_extents[across_axis];
  const double up = local.z() + box->half_extents.z();
  const double in_storey = std::fmod(up, grid.storey_height);
  const double in_bay = std::fmod(along, grid.spacing);
  const bool glass = in_storey >= grid.sill_height && in_storey < grid.sill_height + grid.window_height &&
                     std::abs(in_bay - 0.5 * grid.spacing) < 0.5 * grid.window_width;
  return glass ? 0.0f : primitive.reflectivity;
}

OrientedBox uprightBox(const Eigen::Vector3d& center, const Eigen::Vector3d& size, double yaw) {
  return OrientedBox{center, yawRotation(yaw), 0.5 * size};
}

}  // namespace elo::sim
