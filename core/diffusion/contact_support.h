// Contact support (ours, not in the paper): an object moves only while a hand holds it, and
// its top part turns only while a hand is on the top part. The contact model's sampled maps
// often keep both hands centimetres off the object in such frames (docs/training.md, "Where
// Con is lost"); this reads them as touching there, before guidance and placement use them:
// in a frame that must be held where no hand's map comes within `threshold`, the hand whose
// map comes nearest is taken to touch where its map is smallest (its map shifted down by its
// minimum); the same for the top part's points alone in frames where the hinge turns.
#pragma once

#include <vector>

#include <ATen/core/Tensor.h>

namespace bimart::diffusion {

// maps [S, N, 2, M] (metres), held and turning: per frame (N each), top [N, M] bool (the
// point lies on the top part). Returns the adjusted maps, float32, never below 0.
at::Tensor hold_contacts(const at::Tensor& maps, const std::vector<bool>& held, const std::vector<bool>& turning,
                         const at::Tensor& top, double threshold);

// Frames that must be held: frame t when the object moves from t - 1 to t or from t to t + 1
// (`moving` as core/metrics' object_moving_frames / angle_changing_frames give it).
std::vector<bool> around_motion(const std::vector<bool>& moving);

}  // namespace bimart::diffusion
