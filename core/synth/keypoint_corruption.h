// Predicted keypoints with a diffusion model's typical errors, made from ground truth, to
// test the refinement before the generator exists (issue 7): X = [H | D] (DESIGN §4) from
// the true hands, then
//   - noise: every keypoint and direction vector, every frame, Gaussian (RMS `noise` m);
//   - jitter: each hand's keypoints move together by a Gaussian offset per frame (RMS
//     `jitter` m per frame);
//   - shifts: in random stretches of frames where a hand is near the object, its keypoints
//     sink `shift_min`..`shift_max` into the object (along the mean direction of its
//     nearest keypoints' D), with smooth ramps at both ends. D is left as predicted: the
//     model's contact guess survives its position error, as the refinement assumes.
#pragma once

#include <cstdint>

#include <ATen/core/Tensor.h>

namespace bimart {

struct KeypointCorruption {
  double noise = 0.005;      // m, RMS length of the per-keypoint error
  double jitter = 0.002;     // m, RMS length of the per-frame hand offset
  double shift_min = 0.01;   // m
  double shift_max = 0.02;   // m
  double stretches_per_second = 0.3;  // per hand
  int stretch_min = 10, stretch_max = 30;  // frames
  double near = 0.02;        // m: a hand is near the object when a keypoint's |D| is below this
  void validate() const;     // throws bimart::Error naming the field
};

// X [N, 1200] → a corrupted copy (float32), deterministic for a seed; fps sets the number
// of stretches. Frames shifted per hand are counted into `shifted_frames` when given.
at::Tensor corrupt_hand_features(const at::Tensor& features, double fps, const KeypointCorruption& options,
                                 std::uint64_t seed, int64_t* shifted_frames = nullptr);

}  // namespace bimart
