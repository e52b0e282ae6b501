// Sec. III-D: the rules of the model update that both backends apply per point. The model lives in the
// frame of the latest scan: each model point moves into the new frame and is offered again to the pixel
// or cell it projects to, as is each scan point, and the closest offer wins (closest_wins_key.hpp); a
// pixel no scan point is offered to keeps its model point.
#pragma once

#include "elo/device_types.hpp"

namespace elo {

// Model points observed more than tau_w before `now` are dropped.
ELO_HOST_DEVICE inline bool isCurrent(float now, float observed, float time_window) { return now - observed <= time_window; }

// Which scan pixels join the non-ground model: non-ground ones with a normal.
ELO_HOST_DEVICE inline bool joinsModel(PixelLabel label, const Float3& normal) {
  return label == PixelLabel::nonground && !isZero(normal);
}

// In the spherical fusion, model pixel q offers itself as source q and scan pixel q as source pixels + q.
ELO_HOST_DEVICE inline uint32_t scanSource(uint32_t pixel, uint32_t pixels) { return pixels + pixel; }
ELO_HOST_DEVICE inline bool isScanSource(uint32_t source, uint32_t pixels) { return source >= pixels; }

}  // namespace elo
