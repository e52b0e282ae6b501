// Ground segmentation (Sec. III-C.1) on simulated HDL-64E scans with the sensor's 2 cm range noise,
// scored against the surface the simulator knows behind each point: the share of the ground (road,
// kerbs, sidewalks) labelled ground, by horizontal distance from the sensor, and the share of objects
// labelled ground. docs/ground_segmentation.md quotes what this test prints.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "elo/pipeline/backend.hpp"
#include "elo/sim/simulation.hpp"

namespace elo {
namespace {

struct Share {
  size_t points = 0;
  size_t labelled_ground = 0;
  double percent() const { return points > 0 ? 100.0 * labelled_ground / points : 0.0; }
};

constexpr std::array<double, 7> kBandEdges = {0.0, 5.0, 7.5, 10.0, 20.0, 40.0, 1e9};  // horizontal distance (m)

struct Tally {
  std::array<Share, kBandEdges.size() - 1> ground_by_distance;
  Share ground;
  Share objects;  // everything else: buildings, cars, poles, trees
  size_t labelled_nonground = 0;
  size_t labelled_nonground_at_road_level = 0;  // z < -1.4 m in the sensor frame (the road: -1.73 m)

  void add(const Vec3f& point, bool truly_ground, bool labelled_ground) {
    Share& kind = truly_ground ? ground : objects;
    ++kind.points;
    kind.labelled_ground += labelled_ground;
    if (!labelled_ground) {
      ++labelled_nonground;
      labelled_nonground_at_road_level += point.z() < -1.4f;
    }
    if (!truly_ground) return;
    const double distance = std::hypot(point.x(), point.y());
    for (size_t band = 0; band + 1 < kBandEdges.size(); ++band) {
      if (distance < kBandEdges[band + 1]) {
        ++ground_by_distance[band].points;
        ground_by_distance[band].labelled_ground += labelled_ground;
        break;
      }
    }
  }
};

// Every 10th of 100 scans of the urban world's `curves` drive (seed 1), segmented by the CPU backend.
Tally segmentUrbanDrive() {
  sim::SimulationSpec spec;
  spec.world = sim::WorldFamily::urban;
  spec.trajectory = sim::TrajectoryKind::curves;
  spec.frames = 100;
  spec.seed = 1;
  const sim::Simulation simulation(spec);
  const std::unique_ptr<Backend> backend = makeBackend(spec.config);
  Tally tally;
  for (int frame = 0; frame < simulation.frameCount(); frame += 10) {
    const sim::SimulatedScan scan = simulation.scan(frame);
    backend->projectScan(scan.cloud, 0.0f);
    backend->segmentGround();
    const ScanImage& image = backend->scan();
    for (size_t pixel = 0; pixel < image.image.pixelCount(); ++pixel) {
      if (!image.image.occupied(pixel)) continue;
      const size_t point = static_cast<size_t>(image.point_index[pixel]);
      tally.add(image.image.vertex[pixel], scan.surface[point] == sim::SurfaceKind::ground,
                image.label[pixel] == PixelLabel::ground);
    }
  }
  return tally;
}

TEST(GroundSegmentation, LabelsTheNoisyRoadGroundAtEveryDistanceAndNoObject) {
  const Tally tally = segmentUrbanDrive();
  std::printf("ground labelled ground: %.1f %% of %zu points; objects labelled ground: %.2f %% of %zu\n",
              tally.ground.percent(), tally.ground.points, tally.objects.percent(), tally.objects.points);
  for (size_t band = 0; band < tally.ground_by_distance.size(); ++band) {
    std::printf("  ground %g-%g m: %.1f %% of %zu\n", kBandEdges[band], kBandEdges[band + 1],
                tally.ground_by_distance[band].percent(), tally.ground_by_distance[band].points);
  }
  const double road_level_percent = 100.0 * tally.labelled_nonground_at_road_level / tally.labelled_nonground;
  std::printf("non-ground points below z = -1.4 m: %.1f %% of %zu\n", road_level_percent, tally.labelled_nonground);
  // Measured with ground.rise_tolerance 0.03 m: 92.4 % of the ground, 99.0 % within 5 m, 0.02 % of the
  // objects. Without the tolerance (delta_theta alone) 77.2 % and 49.4 %: the road close in is lost.
  EXPECT_GT(tally.ground.points, 500000u);
  EXPECT_GT(tally.ground.percent(), 90.0);
  EXPECT_GT(tally.ground_by_distance[0].percent(), 97.0);
  for (const Share& band : tally.ground_by_distance) EXPECT_GT(band.percent(), 85.0);
  EXPECT_LT(tally.objects.percent(), 0.1);
}

}  // namespace
}  // namespace elo
