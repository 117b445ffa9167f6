// The frames where a hand must be on the object: an object moves only while a hand holds
// it, and its top part turns only while a hand is on the top part. The frames Con and Art
// count (object_moving_frames, angle_changing_frames) and the frame after each step, so
// both ends of a step are held. Used by the contact support (core/diffusion/contact_support.h)
// and the refinement's hold term (core/refine/refinement.h).
#pragma once

#include <vector>

#include <ATen/core/Tensor.h>

#include "core/object/articulated_object.h"

namespace bimart {

struct HeldFrames {
  std::vector<bool> held;     // the object moves from t - 1 to t or from t to t + 1
  std::vector<bool> turning;  // the hinge angle changes from t - 1 to t or from t to t + 1
};

// Frame t is set when moving[t] or moving[t - 1] is.
std::vector<bool> around_motion(const std::vector<bool>& moving);

// states [N, 7]: N flags each.
HeldFrames held_frames(const ArticulatedObject& object, const at::Tensor& states);

}  // namespace bimart
