// How a sensor that is carried or rides a legged robot moves about the path it follows, which a car's
// body never does: a hand swings it in yaw, the walker's steps rock it and bob it up and down, a trot
// jolts it at every footfall. The simulator applies a gait on top of the route's pose (SensorTrajectory),
// in the sensor's own frame, so that the world is still built along the path.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

namespace elo::sim {

struct Gait {
  double yaw_swing_deg = 0.0;  // amplitude of the yaw swing
  double yaw_swing_hz = 0.0;   // its frequency: the peak turn rate is 2 pi f amplitude
  double sway_deg = 0.0;       // amplitude of the roll and pitch rocking, at half the step rate
  double bob_m = 0.0;          // amplitude of the height's rise and fall, at the step rate
  double step_hz = 0.0;        // steps (footfalls) per second
  // The bob and the roll come as jolts at each footfall (a trot) rather than smoothly (a walk).
  bool jolts = false;

  // The sensor's pose relative to the route's at `time` (s).
  Eigen::Isometry3d offsetAt(double time) const;
};

// A sensor carried by hand at a walk: swung +-30 deg at 1 Hz (188 deg/s at the peak), rocked +-10 deg,
// bobbing 4 cm at 1.8 steps a second.
Gait handheldWalk();
// A sensor on a trotting legged robot: jolts of 3 cm and 4 deg of roll at 3 footfalls a second, and a
// yaw wobble of +-5 deg.
Gait trot();

std::optional<Gait> gaitFromName(const std::string& name);  // "none", "walk", "trot"
std::vector<std::string> gaitNames();

}  // namespace elo::sim
