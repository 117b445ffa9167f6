// Noise schedules of the diffusion models (DESIGN §5): betas, ᾱ_t and the DDPM posterior
// coefficients, for T steps. Index t = 0 is the least noisy step, T - 1 the noisiest.
#pragma once

#include <string>
#include <vector>

#include <ATen/core/Tensor.h>

namespace bimart::diffusion {

struct NoiseSchedule {
  std::string name;                   // "squaredcos_cap_v2" or "linear"
  int steps = 0;                      // T
  double shift = 1;                   // data scale s of the shifted schedule (1 = none)
  std::vector<double> betas;          // [T]
  std::vector<double> alphas_cumprod; // ᾱ_t = Π_{s<=t} (1 - β_s), [T]

  // ᾱ_{t-1}, with ᾱ_{-1} = 1.
  double alpha_cumprod_prev(int t) const { return t > 0 ? alphas_cumprod[t - 1] : 1.0; }
};

// "squaredcos_cap_v2": ᾱ(t) = f(t) / f(0), f(t) = cos²((t/T + 0.008) / 1.008 · π/2), β_t =
// min(1 - ᾱ(t+1)/ᾱ(t), 0.999) (Nichol & Dhariwal's cosine schedule, as in diffusers).
// "linear": β from 1e-4 to 0.02 scaled by 1000/T (Ho et al., rescaled to T steps).
// shift s != 1: every ᾱ_t is replaced by ᾱ s² / (ᾱ s² + 1 − ᾱ), the schedule of the data
// scaled by s (log-SNR shifted by 2 log s; Hoogeboom et al. 2023, "simple diffusion"): s < 1
// noises strongly correlated data — whose few large directions a unit-variance schedule
// leaves readable until the last steps — over more of the steps (docs/training.md, "Shift").
// Throws bimart::Error for another name, steps < 1 or s outside (0, 1].
NoiseSchedule make_schedule(const std::string& name, int steps, double shift = 1.0);

// Forward noising x_t = sqrt(ᾱ_t) x0 + sqrt(1 - ᾱ_t) ε, per batch element: x0, noise
// [B, ...] float32, t [B] int64.
at::Tensor add_noise(const NoiseSchedule& s, const at::Tensor& x0, const at::Tensor& noise,
                     const at::Tensor& t);

// The DDPM posterior q(x_{t-1} | x_t, x0): mean = c0 · x0 + ct · x_t, variance.
struct Posterior {
  double c0 = 0, ct = 0, variance = 0;
};
Posterior posterior(const NoiseSchedule& s, int t);

}  // namespace bimart::diffusion
