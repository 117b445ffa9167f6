// Values a diffusion sampler re-imposes on its clean-sample prediction at every step
// (in-painting, DESIGN §5): the frames, entries or bounds an animator fixed
// (docs/directing.md). Unlike a Guidance, which nudges the prediction, a constraint sets
// it: the result satisfies the constraint, and the denoiser's next steps make the rest of
// the sample agree with it. The contact and motion stages build theirs from the pipeline's
// `hand_constraints` (core/directing/); the sampler applies it window by window
// (core/diffusion/generation.h).
#pragma once

#include <cstdint>

#include <ATen/core/Tensor.h>

namespace bimart {

class SampleConstraint {
 public:
  virtual ~SampleConstraint() = default;

  // x0: [B, T, D] float32, the predicted clean samples of B samples for frames
  // [first_frame, first_frame + T) of the sequence, in the model's units (contact model:
  // D = 2048, the maps [2, 1024] in metres; motion model: D = 1200, X = [H | D] in metres,
  // canonical object frame; a joints model (OMOMO-B): D = 96, both hands' joints, metres,
  // canonical frame). step: the diffusion step, num_steps - 1 (noisiest) down to 0; -1 for
  // the finished sample. Returns x0 with the constraint imposed (same shape); must not
  // modify x0 and must give the same result for the same arguments.
  virtual at::Tensor impose(const at::Tensor& x0, std::int64_t first_frame, int step, int num_steps) const = 0;
};

}  // namespace bimart
