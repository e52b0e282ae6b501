// Test fixture: the map of a simulated sequence for the localization rostest: its every other scan placed
// at its ground-truth pose (in the frame of scan 0), voxelised, written as PCD without normals (the node
// estimates them at load). usage: make_localization_map SEQUENCE_DIR MAP.pcd
#include <cstdio>

#include "../localization/shared_world.hpp"
#include "elo/io/map_pcd.hpp"
#include "elo/io/sequence.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_localization_map SEQUENCE_DIR MAP.pcd\n");
    return 2;
  }
  try {
    const elo::Sequence sequence(argv[1]);
    const std::vector<Eigen::Isometry3d>& truth = sequence.groundTruth();
    elo::MapCloud map = elo::test::mapOfScans(
        [&](int frame) { return std::make_pair(sequence.load(static_cast<size_t>(frame)), truth[static_cast<size_t>(frame)]); },
        static_cast<int>(truth.size()), 2, 0.2, elo::Config().localization.normal_radius);
    map.normals.clear();
    elo::writeMapPcd(argv[2], map);
    std::printf("wrote %zu map points to %s\n", map.size(), argv[2]);
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "make_localization_map: %s\n", error.what());
    return 1;
  }
}
