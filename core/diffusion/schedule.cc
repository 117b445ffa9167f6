#include "core/diffusion/schedule.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"

namespace bimart::diffusion {

NoiseSchedule make_schedule(const std::string& name, int steps, double shift) {
  if (steps < 1) throw Error("noise schedule: steps must be at least 1, got " + std::to_string(steps));
  if (!(shift > 0 && shift <= 1)) throw Error("noise schedule: shift must be in (0, 1], got " + std::to_string(shift));
  NoiseSchedule s;
  s.name = name;
  s.steps = steps;
  s.shift = shift;
  s.betas.resize(static_cast<std::size_t>(steps));
  if (name == "squaredcos_cap_v2") {
    const auto f = [&](double t) {
      const double c = std::cos((t / steps + 0.008) / 1.008 * M_PI / 2.0);
      return c * c;
    };
    for (int t = 0; t < steps; ++t) s.betas[t] = std::min(1.0 - f(t + 1) / f(t), 0.999);
  } else if (name == "linear") {
    const double scale = 1000.0 / steps;
    const double lo = scale * 1e-4, hi = scale * 0.02;
    for (int t = 0; t < steps; ++t) s.betas[t] = steps == 1 ? lo : lo + (hi - lo) * t / (steps - 1);
  } else {
    throw Error("unknown noise schedule '" + name + "' (known: squaredcos_cap_v2, linear)");
  }
  s.alphas_cumprod.resize(s.betas.size());
  double prod = 1.0;
  for (int t = 0; t < steps; ++t) {
    prod *= 1.0 - s.betas[t];
    s.alphas_cumprod[t] = prod;
  }
  if (shift != 1.0) {
    const double s2 = shift * shift;
    double prev = 1.0;
    for (int t = 0; t < steps; ++t) {
      const double a = s.alphas_cumprod[t];
      s.alphas_cumprod[t] = a * s2 / (a * s2 + 1.0 - a);
      s.betas[t] = 1.0 - s.alphas_cumprod[t] / prev;
      prev = s.alphas_cumprod[t];
    }
  }
  return s;
}

at::Tensor add_noise(const NoiseSchedule& s, const at::Tensor& x0, const at::Tensor& noise,
                     const at::Tensor& t) {
  const auto abar = at::tensor(s.alphas_cumprod, at::kDouble).index_select(0, t.to(at::kLong));
  std::vector<int64_t> shape(static_cast<std::size_t>(x0.dim()), 1);
  shape[0] = x0.size(0);
  const auto a = abar.sqrt().to(x0.scalar_type()).view(shape);
  const auto b = (1.0 - abar).sqrt().to(x0.scalar_type()).view(shape);
  return a * x0 + b * noise;
}

Posterior posterior(const NoiseSchedule& s, int t) {
  const double abar = s.alphas_cumprod[t];
  const double abar_prev = s.alpha_cumprod_prev(t);
  const double beta = s.betas[t];
  Posterior p;
  p.c0 = beta * std::sqrt(abar_prev) / (1.0 - abar);
  p.ct = (1.0 - abar_prev) * std::sqrt(1.0 - beta) / (1.0 - abar);
  p.variance = beta * (1.0 - abar_prev) / (1.0 - abar);
  return p;
}

}  // namespace bimart::diffusion
