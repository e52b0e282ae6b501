// Motion compensation of the projected scan, in place (docs/deskew.md): each occupied pixel's vertex
// again from its measured point and time under the new velocity, its normal turned with it. The
// per-pixel math is shared with the CUDA backend (deskew.hpp).
#include <algorithm>
#include <cmath>

#include "core/common/deskew.hpp"
#include "core/common/eigen_interop.hpp"
#include "core/cpu/parallel.hpp"
#include "core/cpu/stages.hpp"

namespace elo::cpu {

namespace {

constexpr size_t kBlock = 1024;

// The pixels [begin, end) of a scan, as the loops below read and write them.
struct PixelBlock {
  const Vec3f* measured;
  const float* time;
  Vec3f* vertex;
  float* range;
  Vec3f* normal;
  size_t begin;
  size_t end;
};

// What the loops below need to know of a block before they run.
struct BlockContents {
  bool occupied;  // some pixel holds a point (the image's top and bottom rows may hold none)
  // Every pixel turns by less than the short series' bound under both velocities, the squared angle
  // computed as coefficientsAt() computes it (at -t, as `applied` is undone, it is the same product), so
  // that both loops take the same coefficients. Empty pixels (with a past scan's times) count too: they
  // can only send a block to the exact loop.
  bool turns_little;
};

BlockContents contentsOf(const SweepVelocity& applied, const SweepVelocity& velocity, const PixelBlock& block) {
  int occupied = 0;
  int much = 0;
  for (size_t pixel = block.begin; pixel < block.end; ++pixel) {
    const float time = block.time[pixel];
    occupied |= block.range[pixel] > 0.0f;
    much |= !(applied.angular_squared * time * time < TwistCoefficients::kSmallSquaredAngle);
    much |= !(velocity.angular_squared * time * time < TwistCoefficients::kSmallSquaredAngle);
  }
  return {occupied != 0, much == 0};
}

// redeskewPixel() on every occupied pixel of a block where both velocities turn little: the coefficients
// without a branch, and every pixel computed and then kept or not, so that the loop vectorises. The
// velocities are copies and the arrays restrict, so that the compiler knows the stores change neither.
void redeskewLittleTurns(const SweepVelocity applied, const SweepVelocity velocity, const PixelBlock& block) {
  const Vec3f* __restrict measured = block.measured;
  const float* __restrict times = block.time;
  Vec3f* __restrict vertices = block.vertex;
  float* __restrict ranges = block.range;
  Vec3f* __restrict normals = block.normal;
  for (size_t pixel = block.begin; pixel < block.end; ++pixel) {
    const float time = times[pixel];
    const TwistCoefficients forward = TwistCoefficients::ofSmallSquaredAngle(velocity.angular_squared * time * time);
    const TwistCoefficients back = TwistCoefficients::ofSmallSquaredAngle(applied.angular_squared * time * time);
    Float3 vertex;
    float range;
    Float3 normal = toFloat3(normals[pixel]);
    redeskewPixelWith(applied, velocity, forward, back, toFloat3(measured[pixel]), time, vertex, range, normal);
    // An empty pixel keeps what it holds (its normal is zero, and stays so).
    const bool occupied = ranges[pixel] > 0.0f;
    vertices[pixel] = toVec3f(choose(occupied, vertex, toFloat3(vertices[pixel])));
    ranges[pixel] = occupied ? range : ranges[pixel];
    normals[pixel] = toVec3f(normal);
  }
}

void redeskewEachPixel(const SweepVelocity& applied, const SweepVelocity& velocity, const PixelBlock& block) {
  for (size_t pixel = block.begin; pixel < block.end; ++pixel) {
    if (block.range[pixel] <= 0.0f) continue;
    Float3 vertex;
    Float3 normal = toFloat3(block.normal[pixel]);
    redeskewPixel(applied, velocity, toFloat3(block.measured[pixel]), block.time[pixel], vertex, block.range[pixel],
                  normal);
    block.vertex[pixel] = toVec3f(vertex);
    block.normal[pixel] = toVec3f(normal);
  }
}

// turnedPixelMoved() on every occupied pixel of a block, every pixel computed and then kept or not, so
// that the loop vectorises (as redeskewLittleTurns()).
void moveTurnedPixels(const SweepVelocity applied, const SweepVelocity velocity, const PixelBlock& block) {
  const float* __restrict times = block.time;
  Vec3f* __restrict vertices = block.vertex;
  float* __restrict ranges = block.range;
  for (size_t pixel = block.begin; pixel < block.end; ++pixel) {
    const Float3 vertex = toFloat3(vertices[pixel]);
    const Float3 moved = turnedPixelMoved(applied, velocity, times[pixel], vertex);
    const bool occupied = ranges[pixel] > 0.0f;
    vertices[pixel] = toVec3f(choose(occupied, moved, vertex));
    ranges[pixel] = occupied ? norm(moved) : ranges[pixel];
  }
}

bool occupiedBlock(const PixelBlock& block) {
  int occupied = 0;
  for (size_t pixel = block.begin; pixel < block.end; ++pixel) occupied |= block.range[pixel] > 0.0f;
  return occupied != 0;
}

template <typename Redeskew>
void forEachBlock(ScanImage& scan, const Redeskew& redeskew) {
  SphericalImage& image = scan.image;
  const size_t pixels = image.pixelCount();
  parallelFor((pixels + kBlock - 1) / kBlock, [&](size_t index) {
    redeskew(PixelBlock{scan.measured.data(), scan.time.data(), image.vertex.data(), image.range.data(),
                        image.normal.data(), index * kBlock, std::min(pixels, (index + 1) * kBlock)});
  });
}

}  // namespace

void deskewScan(const SweepVelocity& applied, const SweepVelocity& velocity, ScanImage& scan) {
  forEachBlock(scan, [&](const PixelBlock& block) {
    const BlockContents contents = contentsOf(applied, velocity, block);
    if (!contents.occupied) return;
    if (contents.turns_little) {
      redeskewLittleTurns(applied, velocity, block);
    } else {
      redeskewEachPixel(applied, velocity, block);
    }
  });
}

void deskewTurnedScan(const SweepVelocity& applied, const SweepVelocity& velocity, ScanImage& scan) {
  forEachBlock(scan, [&](const PixelBlock& block) {
    if (occupiedBlock(block)) moveTurnedPixels(applied, velocity, block);
  });
}

}  // namespace elo::cpu
