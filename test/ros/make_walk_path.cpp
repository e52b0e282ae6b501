// Test fixture: the walks' straight path (test/pipeline/simulated_walks.hpp: 1.4 m/s along the LiDAR's x,
// a pose every 0.1 s) in KITTI's camera frame, which elo_sim --poses takes; elo_sim --gait walk swings
// the sensor about it. usage: make_walk_path FRAMES POSES.txt
#include <cstdio>
#include <string>

#include "../pipeline/simulated_walks.hpp"
#include "elo/io/kitti.hpp"
#include "elo/sim/trajectory.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_walk_path FRAMES POSES.txt\n");
    return 2;
  }
  try {
    const int frames = std::stoi(argv[1]);
    elo::writeKittiPoses(argv[2], elo::lidarToCamera(elo::test::straightPath(frames, 1.4), elo::sim::kittiVeloToCam00()));
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "make_walk_path: %s\n", error.what());
    return 1;
  }
}
