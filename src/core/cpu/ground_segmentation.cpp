// Sec. III-C.1: ground segmentation on the columns of the range image, one column per task; the column
// walk is shared with the CUDA backend (ground.hpp).
#include "core/common/ground.hpp"
#include "core/cpu/image_views.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

void segmentGround(const GroundBand& band, ScanImage& scan) {
  const LabelledPixels pixels(scan);
  parallelFor(static_cast<size_t>(pixels.cols), [&](size_t col) { segmentColumn(pixels, static_cast<int>(col), band); });
}

void labelAllNonground(ScanImage& scan) {
  parallelFor(scan.label.size(), [&](size_t pixel) {
    if (scan.image.occupied(pixel)) scan.label[pixel] = PixelLabel::nonground;
  });
}

}  // namespace elo::cpu
