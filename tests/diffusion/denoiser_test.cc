// The denoiser: shapes, the paper's size builds and runs, a tiny one overfits a fixed
// batch, and the null contact token replaces the contact condition.
#include <gtest/gtest.h>

#include <torch/optim/adam.h>

#include <ATen/ATen.h>

#include "core/diffusion/denoiser.h"
#include "core/util/error.h"

namespace bimart::diffusion {
namespace {

DenoiserConfig tiny(const std::string& model) {
  DenoiserConfig c;
  c.model = model;
  c.sample_size = 12;
  c.object_condition_size = 10;
  c.contact_condition_size = model == "motion" ? 6 : 0;
  c.window = 8;
  c.latent = 32;
  c.layers = 2;
  c.heads = 4;
  c.feedforward = 64;
  c.condition_hidden = 32;
  c.dropout = 0.0;
  return c;
}

TEST(Denoiser, PaperSizeBuildsAndRunsAWindow) {
  torch::manual_seed(0);
  DenoiserConfig c = DenoiserConfig::paper("motion");
  c.dropout = 0.0;
  Denoiser net(c);
  net->eval();
  EXPECT_GT(net->num_parameters(), 20'000'000);
  torch::NoGradGuard ng;
  const at::Tensor cond = net->encode_conditions(at::randn({1, 64, 3079}), at::randn({1, 64, 2048}));
  EXPECT_EQ(cond.sizes(), (std::vector<int64_t>{1, 64, 512}));
  const at::Tensor out = net->forward(at::randn({1, 64, 1200}), at::full({1}, 49, at::kLong), cond);
  EXPECT_EQ(out.sizes(), (std::vector<int64_t>{1, 64, 1200}));
  EXPECT_TRUE(at::isfinite(out).all().item<bool>());
}

TEST(Denoiser, RejectsBadConfigsAndShapes) {
  DenoiserConfig c = tiny("motion");
  c.heads = 5;  // does not divide 32
  EXPECT_THROW(Denoiser{c}, Error);
  Denoiser net(tiny("contact"));
  EXPECT_THROW(net->encode_conditions(at::randn({1, 8, 11})), Error);
  EXPECT_THROW(net->encode_conditions(at::randn({1, 9, 10})), Error);  // longer than the window
  const at::Tensor cond = net->encode_conditions(at::randn({1, 8, 10}));
  EXPECT_THROW(net->forward(at::randn({1, 8, 13}), at::zeros({1}, at::kLong), cond), Error);
}

TEST(Denoiser, OverfitsATinyBatch) {
  torch::manual_seed(1);
  Denoiser net(tiny("motion"));
  const at::Tensor x0 = at::randn({4, 8, 12});
  const at::Tensor obj = at::randn({4, 8, 10}), contact = at::randn({4, 8, 6});
  const at::Tensor xt = at::randn({4, 8, 12});
  const at::Tensor t = at::tensor({3, 10, 25, 40}, at::kLong);
  torch::optim::Adam opt(net->parameters(), torch::optim::AdamOptions(3e-3));
  double first = 0, last = 0;
  for (int i = 0; i < 300; ++i) {
    const at::Tensor pred = net->forward(xt, t, net->encode_conditions(obj, contact));
    const at::Tensor loss = (pred - x0).pow(2).mean();
    if (i == 0) first = loss.item<double>();
    last = loss.item<double>();
    opt.zero_grad();
    loss.backward();
    opt.step();
  }
  EXPECT_GT(first, 0.5);
  EXPECT_LT(last, 0.02 * first) << "first " << first << ", last " << last;
}

TEST(Denoiser, NullTokenReplacesTheContactCondition) {
  torch::manual_seed(2);
  Denoiser net(tiny("motion"));
  torch::NoGradGuard ng;
  const at::Tensor obj = at::randn({2, 8, 10});
  const at::Tensor c1 = at::randn({2, 8, 6}), c2 = at::randn({2, 8, 6});
  const at::Tensor off = at::zeros({2}, at::kBool);
  EXPECT_TRUE(at::equal(net->encode_conditions(obj, c1, off), net->encode_conditions(obj, c2, off)));
  EXPECT_TRUE(at::allclose(net->encode_conditions(obj, c1, off), net->encode_conditions(obj)));
  EXPECT_FALSE(at::allclose(net->encode_conditions(obj, c1), net->encode_conditions(obj, c2)));
  // Mixed: sample 0 with contact, sample 1 with the null token.
  const at::Tensor mixed = net->encode_conditions(obj, c1, at::tensor({1, 0}).to(at::kBool));
  EXPECT_TRUE(at::allclose(mixed[0], net->encode_conditions(obj, c1)[0]));
  EXPECT_TRUE(at::allclose(mixed[1], net->encode_conditions(obj)[1]));
}

TEST(Denoiser, TimestepEmbeddingIsSinusoidal) {
  const at::Tensor e = timestep_embedding(at::tensor({0, 7}, at::kLong), 8);
  EXPECT_NEAR(e[0][0].item<float>(), 0.0f, 1e-7);        // sin(0)
  EXPECT_NEAR(e[0][4].item<float>(), 1.0f, 1e-7);        // cos(0)
  EXPECT_NEAR(e[1][0].item<float>(), std::sin(7.0f), 1e-6);
  EXPECT_NEAR(e[1][5].item<float>(), std::cos(7.0f * std::exp(-std::log(10000.0f) / 4)), 1e-6);
}

}  // namespace
}  // namespace bimart::diffusion
