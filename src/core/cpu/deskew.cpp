// Motion compensation of the projected scan, in place (docs/deskew.md): each occupied pixel's vertex
// again from its measured point and time under the new velocity, its normal turned with it. The
// per-pixel math is shared with the CUDA backend (deskew.hpp).
#include "core/common/deskew.hpp"
#include "core/common/eigen_interop.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

void deskewScan(const SweepVelocity& applied, const SweepVelocity& velocity, ScanImage& scan) {
  SphericalImage& image = scan.image;
  parallelFor(image.pixelCount(), [&](size_t pixel) {
    if (!image.occupied(pixel)) return;
    Float3 vertex;
    Float3 normal = toFloat3(image.normal[pixel]);
    redeskewPixel(applied, velocity, toFloat3(scan.measured[pixel]), scan.time[pixel], vertex, image.range[pixel],
                  normal);
    image.vertex[pixel] = toVec3f(vertex);
    image.normal[pixel] = toVec3f(normal);
  });
}

}  // namespace elo::cpu
