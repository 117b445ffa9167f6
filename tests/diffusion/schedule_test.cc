// Noise schedules against their closed forms; samplers with a perfect x0 predictor; CFG.
#include <gtest/gtest.h>

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>

#include <cmath>

#include "core/diffusion/sampler.h"
#include "core/diffusion/schedule.h"
#include "core/util/error.h"

namespace bimart::diffusion {
namespace {

double cosine_f(double t, int T) {
  const double c = std::cos((t / T + 0.008) / 1.008 * M_PI / 2.0);
  return c * c;
}

TEST(Schedule, CosineAlphaBarMatchesTheClosedForm) {
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  ASSERT_EQ(s.betas.size(), 50u);
  for (int t = 0; t < 50; ++t) {
    if (s.betas[t] >= 0.999) break;  // the cap, at the very end only
    EXPECT_NEAR(s.alphas_cumprod[t], cosine_f(t + 1, 50) / cosine_f(0, 50), 1e-12) << "t = " << t;
  }
  EXPECT_LT(s.alphas_cumprod[0], 1.0);
  EXPECT_GT(s.alphas_cumprod[0], 0.99);   // almost clean at t = 0
  EXPECT_LT(s.alphas_cumprod[49], 1e-3);  // almost pure noise at T - 1
  for (int t = 1; t < 50; ++t) EXPECT_LT(s.alphas_cumprod[t], s.alphas_cumprod[t - 1]);
}

TEST(Schedule, LinearBetasAndProduct) {
  const NoiseSchedule s = make_schedule("linear", 50);
  EXPECT_NEAR(s.betas.front(), 20 * 1e-4, 1e-15);
  EXPECT_NEAR(s.betas.back(), 20 * 0.02, 1e-15);
  double prod = 1;
  for (int t = 0; t < 50; ++t) {
    prod *= 1 - (20e-4 + (0.4 - 20e-4) * t / 49.0);
    EXPECT_NEAR(s.alphas_cumprod[t], prod, 1e-12);
  }
}

TEST(Schedule, RejectsUnknownNamesAndSteps) {
  EXPECT_THROW(make_schedule("cosine", 50), Error);
  EXPECT_THROW(make_schedule("linear", 0), Error);
}

TEST(Schedule, ShiftScalesTheSignalToNoiseRatioByTheSquaredScale) {
  const NoiseSchedule plain = make_schedule("squaredcos_cap_v2", 50);
  const NoiseSchedule shifted = make_schedule("squaredcos_cap_v2", 50, 0.2);
  EXPECT_DOUBLE_EQ(shifted.shift, 0.2);
  double prod = 1.0;
  for (int t = 0; t < 50; ++t) {
    const double a = plain.alphas_cumprod[t], b = shifted.alphas_cumprod[t];
    if (a < 1 - 1e-12 && a > 1e-12) EXPECT_NEAR((b / (1 - b)) / (a / (1 - a)), 0.04, 1e-9) << t;  // SNR × s²
    EXPECT_LT(b, a + 1e-15);
    prod *= 1.0 - shifted.betas[t];  // betas consistent with the new ᾱ
    EXPECT_NEAR(prod, b, 1e-12) << t;
  }
  // Noising with the shifted schedule is noising the scaled data, up to a common factor:
  // x_t' = (sqrt(ᾱ) s x0 + sqrt(1 − ᾱ) ε) / sqrt(ᾱ s² + 1 − ᾱ).
  const int t = 20;
  const double a = plain.alphas_cumprod[t];
  const at::Tensor x0 = at::randn({2, 5}), eps = at::randn({2, 5}), tt = at::full({2}, t, at::kLong);
  const at::Tensor direct = (std::sqrt(a) * 0.2 * x0 + std::sqrt(1 - a) * eps) / std::sqrt(a * 0.04 + 1 - a);
  EXPECT_TRUE(at::allclose(add_noise(shifted, x0, eps, tt), direct, 1e-5, 1e-6));
  EXPECT_EQ(make_schedule("squaredcos_cap_v2", 50, 1.0).alphas_cumprod, plain.alphas_cumprod);
  EXPECT_THROW(make_schedule("squaredcos_cap_v2", 50, 0.0), Error);
  EXPECT_THROW(make_schedule("squaredcos_cap_v2", 50, 1.5), Error);
  EXPECT_THROW(make_schedule("squaredcos_cap_v2", 50, std::nan("")), Error);
}

TEST(Schedule, AddNoiseIsTheClosedForm) {
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  const at::Tensor x0 = at::randn({3, 4, 5});
  const at::Tensor eps = at::randn({3, 4, 5});
  const at::Tensor t = at::tensor({0, 10, 49}, at::kLong);
  const at::Tensor xt = add_noise(s, x0, eps, t);
  for (int b = 0; b < 3; ++b) {
    const double a = s.alphas_cumprod[t[b].item<int64_t>()];
    EXPECT_TRUE(at::allclose(xt[b], std::sqrt(a) * x0[b] + std::sqrt(1 - a) * eps[b], 1e-5, 1e-6));
  }
}

TEST(Schedule, PosteriorMeanOfANoiseFreeSampleIsTheScaledData) {
  // x_t = sqrt(ᾱ_t) x0 exactly -> the posterior mean is sqrt(ᾱ_{t-1}) x0.
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  for (int t : {1, 5, 25, 49}) {
    const Posterior p = posterior(s, t);
    EXPECT_NEAR(p.c0 + p.ct * std::sqrt(s.alphas_cumprod[t]), std::sqrt(s.alphas_cumprod[t - 1]), 1e-12) << t;
    EXPECT_GT(p.variance, 0);
  }
  EXPECT_NEAR(posterior(s, 0).variance, 0.0, 1e-15);
}

TEST(Sampler, TimestepsOfDdpmAndDdim) {
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  const auto ddpm = sampling_timesteps(s, {"ddpm", 0, 0});
  ASSERT_EQ(ddpm.size(), 50u);
  EXPECT_EQ(ddpm.front(), 49);
  EXPECT_EQ(ddpm.back(), 0);
  const auto ddim = sampling_timesteps(s, {"ddim", 10, 0});
  ASSERT_EQ(ddim.size(), 10u);
  EXPECT_EQ(ddim.front(), 49);
  EXPECT_EQ(ddim.back(), 0);
  for (std::size_t i = 1; i < ddim.size(); ++i) EXPECT_LT(ddim[i], ddim[i - 1]);
  EXPECT_THROW(sampling_timesteps(s, {"ddim", 51, 0}), Error);
  EXPECT_THROW(sampling_timesteps(s, {"euler", 0, 0}), Error);
}

TEST(Sampler, ALaterStartVisitsOnlyTheStepsBelowIt) {
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  const auto ddpm = sampling_timesteps(s, {"ddpm", 0, 0, 20});
  ASSERT_EQ(ddpm.size(), 21u);
  EXPECT_EQ(ddpm.front(), 20);
  EXPECT_EQ(ddpm.back(), 0);
  const auto ddim = sampling_timesteps(s, {"ddim", 5, 0, 20});
  EXPECT_EQ(ddim, (std::vector<int>{20, 15, 10, 5, 0}));
  // More DDIM steps than there are below the start: each step once.
  EXPECT_EQ(sampling_timesteps(s, {"ddim", 10, 0, 3}), (std::vector<int>{3, 2, 1, 0}));
  EXPECT_EQ(sampling_timesteps(s, {"ddpm", 0, 0, -1}).front(), 49);
  EXPECT_THROW(sampling_timesteps(s, {"ddpm", 0, 0, 50}), Error);
  EXPECT_THROW(sampling_timesteps(s, {"ddpm", 0, 0, -2}), Error);
}

class PerfectPredictor : public ::testing::TestWithParam<SamplerOptions> {};

TEST_P(PerfectPredictor, ReturnsTheData) {
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  const at::Tensor data = at::randn({2, 8, 6});
  int calls = 0;
  const Predictor perfect = [&](const at::Tensor& x, int) {
    ++calls;
    EXPECT_TRUE(at::isfinite(x).all().item<bool>());
    return data.clone();
  };
  auto gen = at::detail::createCPUGenerator(3);
  const at::Tensor out = sample(s, perfect, at::randn({2, 8, 6}, gen), GetParam(), gen);
  EXPECT_TRUE(at::allclose(out, data, 0, 0));
  EXPECT_EQ(calls, static_cast<int>(sampling_timesteps(s, GetParam()).size()));
}

INSTANTIATE_TEST_SUITE_P(Samplers, PerfectPredictor,
                         ::testing::Values(SamplerOptions{"ddpm", 0, 0}, SamplerOptions{"ddim", 10, 0},
                                           SamplerOptions{"ddim", 10, 1.0}, SamplerOptions{"ddpm", 0, 0, 12},
                                           SamplerOptions{"ddim", 4, 0, 30}));

TEST(Sampler, DdpmStepsTowardTheDataWithAPerfectPredictor) {
  // The iterates approach the data: the distance after the second-last step is far below
  // the starting noise's.
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  const at::Tensor data = at::randn({1, 16, 4});
  double before_last = 0;
  auto gen = at::detail::createCPUGenerator(4);
  const at::Tensor x_T = at::randn({1, 16, 4}, gen);
  sample(s, [&](const at::Tensor&, int) { return data; }, x_T, {"ddpm", 0, 0}, gen,
         [&](int done, int total, at::Tensor& x) {
           if (done == total - 1) before_last = (x - data).norm().item<double>();
         });
  EXPECT_LT(before_last, 0.2 * (x_T - data).norm().item<double>());
}

TEST(Cfg, LambdaZeroIsTheConditionalOutput) {
  const at::Tensor c = at::randn({2, 3}), u = at::randn({2, 3});
  EXPECT_TRUE(at::equal(combine_cfg(c, u, 0.0), c));
  EXPECT_TRUE(at::allclose(combine_cfg(c, u, 0.5), 1.5 * c - 0.5 * u));
}

}  // namespace
}  // namespace bimart::diffusion
