// Sec. III-D: the rules of the model update that both backends apply per point. The model lives in the
// frame of the latest scan: each model point moves into the new frame and is offered again to the pixel
// or cell it projects to, as is each scan point; a pixel no scan point is offered to keeps its model
// point.
//
// Which offer a pixel or cell keeps takes two rounds of closest-wins keys (closest_wins_key.hpp). The
// first finds the closest offer. In the second, the offers on the same surface as the closest one
// (within model.same_surface_distance of its range) compete by age, and the oldest wins; equal ages, as
// the points of one scan have, fall to a hash of the source. A surface in front thus still replaces what it
// hides, as the paper's "closer wins" intends, while the noisy ranges of one surface seen again are not
// filtered for their nearest: which one stays no longer depends on its noise.
#pragma once

#include "core/common/closest_wins_key.hpp"
#include "elo/config.hpp"
#include "elo/device_types.hpp"

namespace elo {

// When and how the model fuses a scan (both backends).
struct ModelFusion {
  float now;                    // the scan's stamp
  float time_window;            // tau_w
  float same_surface_distance;  // model.same_surface_distance

  static ModelFusion fromConfig(const ModelConfig& config, float now) {
    return {now, static_cast<float>(config.time_window), static_cast<float>(config.same_surface_distance)};
  }
};

// Model points observed more than tau_w before `now` are dropped.
ELO_HOST_DEVICE inline bool isCurrent(float now, float observed, float time_window) { return now - observed <= time_window; }

// Which scan pixels join the non-ground model: non-ground ones with a normal.
ELO_HOST_DEVICE inline bool joinsModel(PixelLabel label, const Float3& normal) {
  return label == PixelLabel::nonground && !isZero(normal);
}

// In the spherical fusion, model pixel q offers itself as source q and scan pixel q as source pixels + q.
ELO_HOST_DEVICE inline uint32_t scanSource(uint32_t pixel, uint32_t pixels) { return pixels + pixel; }
ELO_HOST_DEVICE inline bool isScanSource(uint32_t source, uint32_t pixels) { return source >= pixels; }

// Whether an offer at `range` takes part in the second round of a pixel whose closest offer is at
// `closest_range`. The closest offer itself always does.
ELO_HOST_DEVICE inline bool onClosestSurface(float range, float closest_range, float same_surface_distance) {
  return range <= closest_range + same_surface_distance;
}

// Equal stamps are the rule, not the exception: the points of one scan that land in one pixel or cell.
// Which of them stays must not depend on where they lie: "the lower source" (the lower column, the point
// counter-clockwise of the other) kept the counter-clockwise point of every such pair, and the estimated
// heading drifted clockwise on every drive, turning left or right (issue 31, docs/accuracy.md). Equal
// stamps therefore fall to the source that a fixed bijective hash (MurmurHash3's finaliser) ranks first:
// as deterministic as the index, the same on both backends, and blind to the geometry.
ELO_HOST_DEVICE inline uint32_t scrambledSource(uint32_t source) {
  source ^= source >> 16;
  source *= 0x85ebca6bu;
  source ^= source >> 13;
  source *= 0xc2b2ae35u;
  return source ^ (source >> 16);
}
ELO_HOST_DEVICE inline uint32_t unscrambledSource(uint32_t scrambled) {
  scrambled ^= scrambled >> 16;
  scrambled *= 0x7ed1b41du;  // the inverse of 0xc2b2ae35 modulo 2^32
  scrambled ^= (scrambled >> 13) ^ (scrambled >> 26);
  scrambled *= 0xa5cb9243u;  // the inverse of 0x85ebca6b
  return scrambled ^ (scrambled >> 16);
}

// The second round's key: the earliest observation wins, equal stamps fall to the source scrambledSource()
// ranks first. Stamps count from the first scan and are never negative, so their float bits order like
// the times.
ELO_HOST_DEVICE inline ClosestKey oldestWinsKey(float stamp, uint32_t source) {
  return closestWinsKey(stamp, scrambledSource(source));
}
// The source of a second-round key.
ELO_HOST_DEVICE inline uint32_t oldestWinsSource(ClosestKey key) { return unscrambledSource(closestWinsSource(key)); }

// A pixel of a spherical image: its point, normal, range and observation time.
struct ImagePixel {
  Float3 vertex;
  Float3 normal;
  float range;
  float stamp;
};

// What the winning `source` of a fused pixel leaves there: the scan's pixel as observed, or the model's
// point and normal moved into the scan's frame, with the range of the moved point. `scan_pixel(i)` and
// `model_pixel(i)` read pixel i of the scan and of the model, each backend from its own layout (the model
// pixel's range is not read).
template <typename ScanPixel, typename ModelPixel>
ELO_HOST_DEVICE inline ImagePixel fusedPixel(uint32_t source, uint32_t pixels, const Rigid3f& scan_from_model,
                                             const ScanPixel& scan_pixel, const ModelPixel& model_pixel) {
  if (isScanSource(source, pixels)) return scan_pixel(source - pixels);
  const ImagePixel kept = model_pixel(source);
  const Float3 moved = scan_from_model.apply(kept.vertex);
  return {moved, scan_from_model.rotate(kept.normal), norm(moved), kept.stamp};
}

}  // namespace elo
