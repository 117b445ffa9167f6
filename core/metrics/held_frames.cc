#include "core/metrics/held_frames.h"

#include "core/metrics/articulation.h"
#include "core/metrics/contact.h"

namespace bimart {

std::vector<bool> around_motion(const std::vector<bool>& moving) {
  std::vector<bool> held(moving.size(), false);
  for (size_t t = 0; t < moving.size(); ++t) held[t] = moving[t] || (t > 0 && moving[t - 1]);
  return held;
}

HeldFrames held_frames(const ArticulatedObject& object, const at::Tensor& states) {
  return {around_motion(object_moving_frames(object, states)), around_motion(angle_changing_frames(states))};
}

}  // namespace bimart
