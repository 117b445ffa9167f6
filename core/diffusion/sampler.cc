#include "core/diffusion/sampler.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"

namespace bimart::diffusion {

std::vector<int> sampling_timesteps(const NoiseSchedule& s, const SamplerOptions& o) {
  const int T = s.steps;
  if (o.start < -1 || o.start >= T)
    throw Error("the first sampling step must be in [0, " + std::to_string(T - 1) + "] (or -1 = the last), got " +
                std::to_string(o.start));
  const int first = o.start < 0 ? T - 1 : o.start;
  std::vector<int> ts;
  if (o.sampler == "ddpm") {
    for (int t = first; t >= 0; --t) ts.push_back(t);
    return ts;
  }
  if (o.sampler != "ddim") throw Error("unknown sampler '" + o.sampler + "' (known: ddpm, ddim)");
  if (o.steps < 0 || o.steps > T) {
    throw Error("DDIM steps must be in [0, " + std::to_string(T) + "] (0 = all), got " +
                std::to_string(o.steps));
  }
  const int k = std::min(o.steps == 0 ? T : o.steps, first + 1);
  for (int i = 0; i < k; ++i) {
    const double pos = k == 1 ? first : first * (1.0 - static_cast<double>(i) / (k - 1));
    ts.push_back(static_cast<int>(std::lround(pos)));
  }
  return ts;
}

at::Tensor sample(const NoiseSchedule& s, const Predictor& predict, at::Tensor x,
                  const SamplerOptions& o, at::Generator gen, const StepHook& hook) {
  const std::vector<int> ts = sampling_timesteps(s, o);
  const bool ddim = o.sampler == "ddim";
  at::Tensor x0;
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const int t = ts[i];
    x0 = predict(x, t);
    const bool last = i + 1 == ts.size();
    if (last) {
      x = x0;
    } else if (!ddim) {
      const Posterior p = posterior(s, t);
      x = p.c0 * x0 + p.ct * x;
      if (p.variance > 0) x = x + std::sqrt(p.variance) * at::randn(x.sizes(), gen, x.options());
    } else {
      const int t_prev = ts[i + 1];
      const double a = s.alphas_cumprod[t], a_prev = s.alphas_cumprod[t_prev];
      const at::Tensor eps = (x - std::sqrt(a) * x0) / std::sqrt(1.0 - a);
      const double sigma =
          o.eta * std::sqrt((1.0 - a_prev) / (1.0 - a) * (1.0 - a / a_prev));
      x = std::sqrt(a_prev) * x0 + std::sqrt(std::max(1.0 - a_prev - sigma * sigma, 0.0)) * eps;
      if (sigma > 0) x = x + sigma * at::randn(x.sizes(), gen, x.options());
    }
    if (hook) hook(static_cast<int>(i + 1), static_cast<int>(ts.size()), x);
  }
  return x;
}

at::Tensor combine_cfg(const at::Tensor& cond, const at::Tensor& uncond, double lambda) {
  if (lambda == 0.0) return cond;
  return (1.0 + lambda) * cond - lambda * uncond;
}

}  // namespace bimart::diffusion
