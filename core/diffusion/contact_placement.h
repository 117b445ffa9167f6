// Contact placement (ours, not in the paper): each hand translated, frame by frame, so that
// its keypoints meet the object points its contact map C marks as touched.
//
// The paper's guidance takes one gradient step of length λ_c per diffusion step; it bends
// keypoints locally and cannot carry a hand that the model put 5–20 cm off its contacts
// (docs/training.md, "Placement"). This moves the whole hand: per sample, frame and hand,
// translation-only ICP over the points with C < `threshold` (each such point p wants its
// nearest keypoint k at distance C from it: the target is p + C·(k − p)/|k − p|), then a
// Gaussian smoothing over frames weighted by whether the frame had contacts, so the
// translation is continuous and fades out of contact-free stretches.
#pragma once

#include <ATen/core/Tensor.h>

namespace bimart::diffusion {

struct PlacementOptions {
  double threshold = 0.01;  // m: object points with C below this are contacts
  int iterations = 8;       // ICP rounds (nearest keypoints re-found each round)
  int min_points = 4;       // fewer contacts than this in a frame: no translation there
  double sigma = 2.0;       // frames: the smoothing's standard deviation; 0 = none
  // A hand whose map's minimum m lies in [threshold, snap) is taken to touch where its map
  // is smallest: its map is read as C − m. (A sampled map is often a blurred one, its
  // minimum a few cm where the data's is 0.) snap <= threshold: off.
  double snap = 0;
  // m: keypoints are placed this much closer to (> 0: into) the object than their map says.
  double depth = 0;
  void validate() const;    // throws bimart::Error naming the option
};

// Keypoints H [B, T, 2, J, 3], object points P [T, M, 3], contact maps C [B, T, 2, M]
// (metres, one frame): the translation of every hand [B, T, 2, 3], float32.
at::Tensor contact_translations(const at::Tensor& keypoints, const at::Tensor& object_points,
                                const at::Tensor& contact_maps, const PlacementOptions& options = {});

// Per-frame translations δ [B, T, 2, 3] with weights w [B, T, 2] (1 where a frame has one)
// smoothed over frames: Σ g w δ / max(Σ g w, 1), g a Gaussian of `sigma` frames with
// g(0) = 1, so inside a stretch of weighted frames it is a weighted mean and it fades to 0
// within ~σ frames outside. sigma 0: δ·w.
at::Tensor smooth_over_frames(const at::Tensor& delta, const at::Tensor& w, double sigma);

}  // namespace bimart::diffusion
