// Contact-map guidance (DESIGN §5, paper eq. 5-6): from the predicted clean keypoints H,
// the contact map they imply — for each of the 1024 object points of a frame, the distance
// to the nearest of the hand's J keypoints — is compared with the target map C; the
// correction is minus the gradient of the mean squared difference with respect to H,
// scaled to norm `scale` per sample (λ_c = 1 / ||∇||). D is moved by the opposite of H's
// correction, so H + D (the surface point each keypoint refers to) stays put.
//
// The gradient is analytic (only the nearest keypoint of each object point carries it),
// not autograd: nearest keypoints by brute force over the J keypoints, frames and hands in
// parallel, with no temporaries (core/diffusion/contact_guidance.cc).
#pragma once

#include <cstdint>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/diffusion/contact_placement.h"
#include "stages/guidance.h"

namespace bimart::diffusion {

class ContactMapGuidance : public Guidance {
 public:
  // object_points [N, 1024, 3] (canonical frame, articulated: basis_hit_points), target
  // contact maps [N, 2, 1024] or [S, N, 2, 1024] (m). scale: norm of the correction per
  // sample; 0 turns guidance off.
  ContactMapGuidance(at::Tensor object_points, at::Tensor target, double scale = 1.0);

  // Also translate each hand onto its contacts (core/diffusion/contact_placement.h) at the
  // last `steps` diffusion steps (0 = never, the paper's method): `placement`, which the
  // sampler applies to the prediction after classifier-free guidance.
  void set_placement(int steps, const PlacementOptions& options = {});
  // With the placement, also put a hand on the object where it must be held and none is
  // (core/diffusion/contact_support.h, support_translations): `held` and `turning` per frame
  // (N each), `top` [N, 1024] bool (the point lies on the top part), `reach` m; may_hold,
  // may_hold_top [N, 2] bool (optional): the hands that may be put there (docs/directing.md).
  void set_support(std::vector<bool> held, std::vector<bool> turning, at::Tensor top, double reach,
                   at::Tensor may_hold = {}, at::Tensor may_hold_top = {});
  // No gradient correction at the last `steps` diffusion steps (t < steps; 0 = every step,
  // the paper's): the denoiser's last predictions re-form the hands the correction bent.
  void set_release(int steps);

  at::Tensor correction(const at::Tensor& x0, std::int64_t first_frame, int step, int num_steps) const override;
  at::Tensor placement(const at::Tensor& x0, std::int64_t first_frame, int step, int num_steps) const override;

  // The contact map implied by keypoints H [B, T, 2, J, 3] for object points [T, 1024, 3]:
  // [B, T, 2, 1024], and the index of the nearest keypoint [B, T, 2, 1024].
  static std::pair<at::Tensor, at::Tensor> keypoint_contact_map(const at::Tensor& keypoints,
                                                                const at::Tensor& object_points);
  // Mean squared difference between the map implied by x0's keypoints and the target, per
  // sample [B] (for tests and logs).
  at::Tensor discrepancy(const at::Tensor& x0, std::int64_t first_frame) const;

 private:
  at::Tensor targets(std::int64_t first, std::int64_t T, std::int64_t B) const;
  void check_window(const at::Tensor& x0, std::int64_t first) const;  // throws unless [B, T, 1200] inside
  at::Tensor points_;  // [N, 1024, 3] float32
  at::Tensor target_;  // [S, N, 2, 1024] float32
  double scale_;
  int place_steps_ = 0;
  PlacementOptions placement_;
  bool support_ = false;
  std::vector<bool> held_, turning_;
  at::Tensor top_;  // [N, 1024] bool
  at::Tensor may_hold_, may_hold_top_;  // [N, 2] bool or undefined
  double reach_ = 0.01;
  int release_steps_ = 0;
};

}  // namespace bimart::diffusion
