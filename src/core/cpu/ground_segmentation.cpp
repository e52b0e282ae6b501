// Sec. III-C.1: ground segmentation on the columns of the range image. A ground point lies in the band
// around the expected road height and rises by less than delta_theta towards the next occupied pixel
// above and below it in its column (PAPER_NOTES: the two height conditions as printed cannot both hold).
#include <cmath>

#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

namespace {

bool gentleSlope(const Vec3f& a, const Vec3f& b, float max_tangent) {
  const float rise = std::abs(a.z() - b.z());
  const float run = std::hypot(a.x() - b.x(), a.y() - b.y());
  return rise <= max_tangent * run;
}

}  // namespace

void segmentGround(const GroundConfig& config, ScanImage& scan) {
  const SphericalImage& image = scan.image;
  const float road = static_cast<float>(-config.sensor_height);
  const float lowest = road - static_cast<float>(config.band_below);
  const float highest = road + static_cast<float>(config.band_above);
  const float max_tangent = static_cast<float>(std::tan(config.max_slope_deg * M_PI / 180.0));
  const int rows = image.rows;
  const int cols = image.cols;

  parallelFor(static_cast<size_t>(cols), [&](size_t col) {
    int previous = -1;  // pixel of the occupied row above the current one
    int current = -1;
    const auto classify = [&](int above, int pixel, int below) {
      const Vec3f& p = image.vertex[pixel];
      bool ground = p.z() > lowest && p.z() < highest && (above >= 0 || below >= 0);
      if (ground && above >= 0) ground = gentleSlope(p, image.vertex[above], max_tangent);
      if (ground && below >= 0) ground = gentleSlope(p, image.vertex[below], max_tangent);
      scan.label[pixel] = ground ? PixelLabel::ground : PixelLabel::nonground;
    };
    for (int row = 0; row < rows; ++row) {
      const int pixel = row * cols + static_cast<int>(col);
      if (!image.occupied(pixel)) continue;
      if (current >= 0) classify(previous, current, pixel);
      previous = current;
      current = pixel;
    }
    if (current >= 0) classify(previous, current, -1);
  });
}

void labelAllNonground(ScanImage& scan) {
  parallelFor(scan.label.size(), [&](size_t pixel) {
    if (scan.image.occupied(pixel)) scan.label[pixel] = PixelLabel::nonground;
  });
}

}  // namespace elo::cpu
