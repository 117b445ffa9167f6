// Stage kind "guidance": builds a strategy the motion sampler applies inside its loop,
// at every diffusion step, to the predicted clean sample (DESIGN §5, paper eq. 5-7). The
// stage runs once, before the motion stage, and outputs the strategy; the motion stage
// takes it as its optional `guidance` input.
#pragma once

#include <cstdint>
#include <memory>

#include <ATen/core/Tensor.h>

#include "core/object/articulated_object.h"
#include "core/pipeline/stage.h"

namespace bimart {

// A correction of the sampler's clean-sample prediction.
class Guidance {
 public:
  virtual ~Guidance() = default;

  // x0: [B, T, 1200] float32, the predicted clean X of B samples for frames
  // [first_frame, first_frame + T) of the sequence, not normalised: metres, canonical
  // object frame, the layout of the motion stage's `hand_keypoints`. step: the diffusion
  // step of the prediction, num_steps - 1 (noisiest) down to 0.
  //
  // Returns the correction, [B, T, 1200] float32: the sampler uses x0 + correction. The
  // guidance owns its step size (contact-map guidance: minus the gradient of its loss over
  // its norm), so the sampler adds it unscaled. The sampler applies it to the conditional
  // prediction before combining it with the unconditional one (classifier-free guidance).
  // Must not modify x0, and must give the same result for the same arguments.
  virtual at::Tensor correction(const at::Tensor& x0, std::int64_t first_frame, int step,
                                int num_steps) const = 0;

  // A second correction, of the prediction the sampler goes on with: after classifier-free
  // guidance has combined the conditional and unconditional predictions (and the temporal
  // band has filtered them). For corrections that set where something is rather than push
  // it (contact placement): applied before CFG, a translation δ would end up as
  // (1 + λ_f)·δ. Same arguments and units as `correction`; returns the change [B, T, 1200]
  // or an undefined tensor for none (the default).
  virtual at::Tensor placement(const at::Tensor& x0, std::int64_t first_frame, int step, int num_steps) const {
    (void)x0, (void)first_frame, (void)step, (void)num_steps;
    return {};
  }
};

// Either of Guidance's two corrections (`&Guidance::correction`, `&Guidance::placement`), for
// samplers that apply both the same way, window by window.
using GuidanceCorrection = at::Tensor (Guidance::*)(const at::Tensor&, std::int64_t, int, int) const;

class GuidanceStage : public Stage {
 public:
  static constexpr const char* kKind = "guidance";

  static void declare(StageSpec& s) {
    s.input<at::Tensor>("contact_maps",
                        "C: [N, 2, 1024] float32, metres, the target contact maps")
        .input<ArticulatedObject>("object", "the two-part object in its canonical frame, metres")
        .input<at::Tensor>("object_states",
                           "[N, 7] float32: per frame [angle, rx, ry, rz, tx, ty, tz] (rad, m)")
        .input<at::Tensor>(
            "basis_hit_indices",
            "[N, 1024] int64 into [top; bottom] vertices: the object points C refers to")
        .output<std::shared_ptr<const Guidance>>(
            "guidance", "the strategy, valid for the N frames of its inputs");
  }
};

}  // namespace bimart
