// The ground the scans show against ground.sensor_height (issue 44). Ground segmentation looks for the
// road at -sensor_height: a sensor mounted 0.73 m high under a configuration that says 1.73 m finds no
// road in any scan, and the registration loses the ground term without a word (a trotting robot's
// VLP-16 scored 2209 % that way, 3.3 % with the right height). The check fits the plane most points
// below the sensor lie on, takes the median of its distance over recent scans, and says so when it lies
// far from the configured height, naming the value that fits, as normalReachWarning() does for normals.
#pragma once

#include <deque>
#include <optional>
#include <string>

#include "elo/types.hpp"

namespace elo {

// The configured height is taken as right within this (m): kerbs, slopes and a sensor's sway move the
// fitted plane by centimetres to a decimetre.
constexpr double kSensorHeightTolerance = 0.25;

// The sensor's height above the ground in `cloud` (m): the distance from the sensor to the plane that
// most of every `stride`-th point within 2-12 m horizontally and below the sensor lie on, whose normal
// is within 30 deg of the sensor's z axis (a tilted, hand-held sensor too). Nullopt when no such plane
// holds enough of them (a scan without ground in view).
std::optional<double> groundHeightBelow(const PointCloud& cloud, size_t stride);

class SensorHeightCheck {
 public:
  explicit SensorHeightCheck(double configured_height) : configured_(configured_height) {}

  // Adds `cloud`'s ground height; returns a warning when the median of the recent ones lies more than
  // kSensorHeightTolerance from the configured height and did not at the warning before (so a wrong
  // height is told once, and again if it goes away and comes back); empty otherwise.
  std::string add(const PointCloud& cloud);
  // The median of the recent ground heights; nullopt before any.
  std::optional<double> measured() const;

 private:
  double configured_;
  std::deque<double> recent_;
  bool warned_ = false;
};

}  // namespace elo
