// Reverse diffusion from noise to a clean sample for models that predict x0 (DESIGN §5):
// DDPM over every step (the method's default) and DDIM over a sub-sequence of steps, plus
// the classifier-free guidance combination. The model, its conditions and any guidance
// live in the predictor; the sampler only walks the schedule.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <ATen/core/Generator.h>
#include <ATen/core/Tensor.h>

#include "core/diffusion/schedule.h"

namespace bimart::diffusion {

// x0 prediction for the noisy sample x_t at schedule step t (same shape as x_t).
using Predictor = std::function<at::Tensor(const at::Tensor& x_t, int t)>;
// Called after each step with (steps done, steps in all) and the current x; may change x in
// place (e.g. in-painting of frames already known) or do nothing.
using StepHook = std::function<void(int done, int total, at::Tensor& x)>;

struct SamplerOptions {
  std::string sampler = "ddpm";  // "ddpm" or "ddim"
  int steps = 0;                 // DDIM steps (0 = all T); DDPM always takes all T
  double eta = 0.0;              // DDIM noise: 0 = deterministic, 1 = DDPM-like
  int start = -1;                // the noisiest step visited (-1 = T-1); lower starts from a
                                 // partly noised sample (SDEdit), e.g. for `bimart model check --from`
};

// The schedule steps visited, noisiest first: S, ..., 0 for DDPM; for DDIM `steps` values
// spread evenly over [0, S], both ends included (S = start, or T-1). Throws for a bad
// sampler name, steps outside [0, T] or start outside [-1, T-1].
std::vector<int> sampling_timesteps(const NoiseSchedule& s, const SamplerOptions& o);

// Runs the reverse process from x_T (noise, [B, ...]) and returns the clean sample: the
// last step's x0 prediction. Fresh noise is drawn with `gen` (DDPM, DDIM with eta > 0).
at::Tensor sample(const NoiseSchedule& s, const Predictor& predict, at::Tensor x_T,
                  const SamplerOptions& o, at::Generator gen, const StepHook& hook = {});

// Classifier-free guidance (paper eq. 7): (1 + λ) · cond − λ · uncond; λ = 0 gives cond.
at::Tensor combine_cfg(const at::Tensor& cond, const at::Tensor& uncond, double lambda);

}  // namespace bimart::diffusion
