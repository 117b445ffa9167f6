#include "core/metrics/penetration.h"

namespace bimart {

FrameCount penetration_frames(const FrameDepths& depths, double threshold) {
  FrameCount c;
  for (size_t t = 0; t < depths.size(); ++t) {
    ++c.frames;
    if (depths.whole(t) > threshold) ++c.hits;
  }
  return c;
}

FrameCount cavity_frames(const FrameDepths& depths) {
  FrameCount c;
  c.frames = static_cast<std::int64_t>(depths.cavity.size());
  for (double d : depths.cavity) c.hits += d > kCavityDepth;
  return c;
}

}  // namespace bimart
