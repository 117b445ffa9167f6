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

#include "core/metrics/held_frames.h"  // around_motion, held_frames

namespace bimart::diffusion {

// maps [S, N, 2, M] (metres), held and turning: per frame (N each), top [N, M] bool (the
// point lies on the top part). Returns the adjusted maps, float32, never below 0.
// may_hold, may_hold_top [N, 2] bool (optional, docs/directing.md): the hands that may be
// taken to hold the object, its top part, in each frame; undefined: both.
at::Tensor hold_contacts(const at::Tensor& maps, const std::vector<bool>& held, const std::vector<bool>& turning,
                         const at::Tensor& top, double threshold, const at::Tensor& may_hold = {},
                         const at::Tensor& may_hold_top = {});

// Support placement: the translations [B, T, 2, 3] that put a hand on the object where it
// must be held, from the keypoints themselves rather than the maps. In a `held` frame where
// no hand comes within `reach` of the object points P [T, M, 3], the hand that comes
// nearest is moved by the vector from its keypoint to that keypoint's nearest point (so the
// two meet). A hand's distance is its 3rd nearest keypoint's, not its nearest: the model
// leaves a stray keypoint now and then, and the fitted hand is where the others are; then the same over the top part's points (`top` [T, M] bool) in `turning` frames.
// Smoothed over frames like contact_translations (sigma in frames). keypoints [B, T, 2, J, 3].
// may_hold, may_hold_top [T, 2] bool (optional): as for hold_contacts.
at::Tensor support_translations(const at::Tensor& keypoints, const at::Tensor& object_points,
                                const std::vector<bool>& held, const std::vector<bool>& turning, const at::Tensor& top,
                                double reach, double sigma, const at::Tensor& may_hold = {},
                                const at::Tensor& may_hold_top = {});


}  // namespace bimart::diffusion
