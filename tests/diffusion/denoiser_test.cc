// The denoiser: shapes, the paper's size builds and runs, a tiny one overfits a fixed
// batch, and the null contact token replaces the contact condition.
#include <gtest/gtest.h>

#include <torch/optim/adam.h>

#include <ATen/ATen.h>

#include "core/diffusion/denoiser.h"
#include "core/diffusion/schedule.h"
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

// Before any training, the Gaussian skip (unit variances until fitted) already recovers the
// data at the least noisy step (x0 ≈ √ᾱ x_t up to √(1−ᾱ_0) ≈ 0.04 times the network's
// output), where the network that outputs x0 directly is as far off as the data's spread;
// at the noisiest step (ᾱ ≈ 0) the prediction is the network's output alone.
TEST(Denoiser, GaussianSkipRecoversTheDataAtLowNoiseBeforeTraining) {
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  const at::Tensor x0 = at::randn({3, 8, 12}), obj = at::randn({3, 8, 10});
  const auto error_at = [&](const std::string& output, int step) {
    torch::manual_seed(4);
    DenoiserConfig c = tiny("contact");
    c.output = output;
    Denoiser net(c);
    torch::NoGradGuard ng;
    const at::Tensor t = at::full({3}, step, at::kLong);
    const at::Tensor xt = add_noise(s, x0, at::randn(x0.sizes()), t);
    const at::Tensor cond = net->encode_conditions(obj);
    const at::Tensor pred = predict_x0(*net, s, xt, t, cond);
    if (step == 49 && output == "gaussian")
      EXPECT_TRUE(at::allclose(pred, net->forward(xt, t, cond), 0.0, 0.02));  // ᾱ_49 ≈ 1e-5
    return (pred - x0).pow(2).mean().item<double>();
  };
  EXPECT_LT(error_at("gaussian", 0), 0.01);
  EXPECT_GT(error_at("x0", 0), 0.5);
  EXPECT_GT(error_at("gaussian", 49), 0.5);
  DenoiserConfig bad = tiny("contact");
  bad.output = "eps";
  EXPECT_THROW(bad.validate(), Error);
}

// With the network's output at zero, the fitted Gaussian skip is the Wiener filter: for
// data in a 2-dimensional subspace of 12 (variances 8 and 4) its error at every step is
// the closed form Σ λ(1−ᾱ)/(ᾱλ + 1 − ᾱ) / D, and the subspace and variances are recovered
// from samples.
TEST(Denoiser, FittedGaussianSkipIsTheWienerFilter) {
  torch::manual_seed(5);
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  const at::Tensor basis = std::get<0>(at::linalg_qr(at::randn({12, 2}, at::kDouble))).to(at::kFloat);
  const at::Tensor lambda = at::tensor({8.0f, 4.0f});
  const auto draw = [&](int64_t n) { return at::matmul(at::randn({n, 2}) * lambda.sqrt(), basis.t()); };
  const auto [dirs, vars] = principal_directions(draw(40000), 2);
  EXPECT_NEAR(vars[0].item<double>(), 8.0, 0.25);
  EXPECT_NEAR(vars[1].item<double>(), 4.0, 0.15);
  EXPECT_NEAR(at::matmul(dirs.t(), basis).abs().sum().item<double>(), 2.0, 0.02);  // same plane

  DenoiserConfig c = tiny("contact");
  c.output = "gaussian";
  c.skip_rank = 2;
  Denoiser net(c);
  net->set_gaussian_skip(dirs, vars);
  torch::NoGradGuard ng;
  for (auto& p : net->named_parameters())
    if (p.key().rfind("output.", 0) == 0) p.value().zero_();
  const at::Tensor x0 = draw(4 * 8 * 500).view({4 * 500, 8, 12});
  const at::Tensor cond = net->encode_conditions(at::randn({x0.size(0), 8, 10}));
  for (int step : {0, 10, 25, 40, 49}) {
    const double a = s.alphas_cumprod[step];
    const at::Tensor t = at::full({x0.size(0)}, step, at::kLong);
    const at::Tensor xt = add_noise(s, x0, at::randn(x0.sizes()), t);
    const double err = (predict_x0(*net, s, xt, t, cond) - x0).pow(2).mean().item<double>();
    const double expected = (8 * (1 - a) / (a * 8 + 1 - a) + 4 * (1 - a) / (a * 4 + 1 - a)) / 12;
    EXPECT_NEAR(err, expected, 0.05 * expected + 1e-4) << "step " << step;
  }
  EXPECT_THROW(net->set_gaussian_skip(at::randn({12, 3}), at::ones({3})), Error);
}

// The temporal skip filters in (DCT frequency × direction): for data constant over the
// window's 8 frames (all variance at frequency 0) it removes the noise of every other
// frequency, and its error is the closed form over the (frequency, direction) variances —
// far below what the per-frame filter achieves on the same data.
TEST(Denoiser, TemporalSkipFiltersOverTimeToo) {
  torch::manual_seed(6);
  const at::Tensor q = dct_matrix(8);
  EXPECT_TRUE(at::allclose(at::matmul(q, q.t()), at::eye(8), 1e-5, 1e-5));
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  const at::Tensor basis = std::get<0>(at::linalg_qr(at::randn({12, 2}, at::kDouble))).to(at::kFloat);
  const at::Tensor lambda = at::tensor({8.0f, 4.0f});
  const at::Tensor x0 = at::matmul(at::randn({2000, 1, 2}) * lambda.sqrt(), basis.t()).expand({2000, 8, 12}).contiguous();
  const auto [dirs, per_frame] = principal_directions(x0.reshape({-1, 12}), 2);
  const at::Tensor v = at::matmul(q, at::matmul(x0, dirs)).pow(2).mean(0);  // [8, 2]
  EXPECT_NEAR(v[0][0].item<double>(), 8 * 8.0, 4.0);
  EXPECT_LT(v.slice(0, 1).abs().max().item<double>(), 1e-6);

  const auto error_at = [&](const std::string& output, int step) {
    DenoiserConfig c = tiny("contact");
    c.output = output;
    c.skip_rank = 2;
    Denoiser net(c);
    net->set_gaussian_skip(dirs, output == "temporal" ? v : per_frame);
    torch::NoGradGuard ng;
    for (auto& p : net->named_parameters())
      if (p.key().rfind("output.", 0) == 0) p.value().zero_();
    const at::Tensor t = at::full({x0.size(0)}, step, at::kLong);
    const at::Tensor xt = add_noise(s, x0, at::randn(x0.sizes()), t);
    return (predict_x0(*net, s, xt, t, net->encode_conditions(at::randn({x0.size(0), 8, 10}))) - x0)
        .pow(2).mean().item<double>();
  };
  for (int step : {10, 25, 40}) {
    const double a = s.alphas_cumprod[step];
    double expected = 0;
    for (double lam : {8.0, 4.0}) expected += 8 * lam * (1 - a) / (a * 8 * lam + 1 - a) / (8 * 12);
    const double temporal = error_at("temporal", step), per_frame_error = error_at("gaussian", step);
    EXPECT_NEAR(temporal, expected, 0.06 * expected) << "step " << step;
    EXPECT_LT(temporal, 0.5 * per_frame_error) << "step " << step;
  }
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

// A small motion model with the real condition sizes, which the contact cue needs.
DenoiserConfig small_cue_model(bool cue) {
  DenoiserConfig c = tiny("motion");
  c.object_condition_size = 3079;
  c.contact_condition_size = 2048;
  c.contact_cue = cue;
  return c;
}

TEST(Denoiser, ContactCueReadsTheInputsBeforeNormalisation) {
  // Raw object features and contact maps, normalised with two different frames: a model
  // that sees C only through the cue (C's own input columns zeroed, the object MLP's output
  // zeroed) must give the same conditions for both.
  torch::manual_seed(4);
  Denoiser net(small_cue_model(true));
  torch::NoGradGuard ng;
  auto& first = *net->named_parameters().find("contact_mlp.0.weight");
  first.slice(1, 0, 2048).zero_();
  for (const char* name : {"object_mlp.4.weight", "object_mlp.4.bias"}) net->named_parameters().find(name)->zero_();
  at::Tensor obj = at::randn({2, 8, 3079}) * 0.1;
  obj.select(2, 3078).fill_(2.5);                  // s_o
  const at::Tensor C = at::rand({2, 8, 2048}) * 0.2;  // metres
  const at::Tensor basis = at::randn({1024, 3}) * 0.5;
  at::Tensor conds[2];
  for (int k = 0; k < 2; ++k) {
    const at::Tensor om = at::randn({3079}) * 0.1, os = at::rand({3079}) + 0.5;
    const at::Tensor cm = at::rand({2048}) * 0.1, cs = at::rand({2048}) + 0.5;
    net->set_cue_frame(om, os, cm, cs, basis, true);
    conds[k] = net->encode_conditions((obj - om) / os, (C - cm) / cs);
  }
  EXPECT_TRUE(at::allclose(conds[0], conds[1], 1e-4, 1e-5)) << (conds[0] - conds[1]).abs().max().item<float>();
  // ... and the cue does enter: a different contact map changes the conditions.
  EXPECT_FALSE(at::allclose(conds[1], net->encode_conditions(obj, C.flip(2)), 1e-4, 1e-5));
  EXPECT_THROW(net->set_cue_frame(at::zeros({3}), at::ones({3079}), at::zeros({2048}), at::ones({2048}), basis, true),
               Error);
  EXPECT_THROW(Denoiser(small_cue_model(true))->encode_conditions(at::zeros({1, 4, 10})), Error);
}

TEST(Denoiser, ContactPointsReadThePointsNearestToEachHand) {
  // The point encoder reads only each hand's K nearest points: moving a far point's position
  // or distance changes nothing; moving a near one does. Normalisation frames cancel as for
  // the cue.
  torch::manual_seed(5);
  DenoiserConfig config = small_cue_model(false);
  config.contact_points = 8;
  config.point_hidden = 16;
  Denoiser net(config);
  torch::NoGradGuard ng;
  auto& first = *net->named_parameters().find("contact_mlp.0.weight");
  first.zero_();  // C enters through the point encoder only
  for (const char* name : {"object_mlp.4.weight", "object_mlp.4.bias"}) net->named_parameters().find(name)->zero_();
  at::Tensor obj = at::randn({1, 3, 3079}) * 0.1;
  obj.select(2, 3078).fill_(2.0);
  at::Tensor C = 0.3 + at::rand({1, 3, 2048}) * 0.2;  // metres, all far ...
  C.slice(2, 0, 8).fill_(0.01);                          // ... but 8 points near the left hand
  C.slice(2, 1024 + 100, 1024 + 108).fill_(0.02);        // and 8 near the right
  const at::Tensor basis = at::randn({1024, 3}) * 0.5;
  net->set_cue_frame(at::zeros({3079}), at::ones({3079}), at::zeros({2048}), at::ones({2048}), basis, true);
  const at::Tensor base = net->encode_conditions(obj, C);
  at::Tensor far = C.clone();
  far.select(2, 500).add_(0.1);  // a far point's distance
  at::Tensor moved = obj.clone();
  moved.select(2, 3 * 600).add_(0.3);  // a far point's position (x of point 600)
  EXPECT_TRUE(at::allclose(base, net->encode_conditions(obj, far)));
  EXPECT_TRUE(at::allclose(base, net->encode_conditions(moved, C)));
  at::Tensor near = obj.clone();
  near.select(2, 3 * 3).add_(0.3);  // x of point 3, near the left hand
  EXPECT_FALSE(at::allclose(base, net->encode_conditions(near, C), 1e-4, 1e-5));
  at::Tensor nearer = C.clone();
  nearer.select(2, 1024 + 104).fill_(0.0);
  EXPECT_FALSE(at::allclose(base, net->encode_conditions(obj, nearer), 1e-4, 1e-5));
  // Normalised inputs give the same conditions once the frame says how they were normalised.
  const at::Tensor om = at::randn({3079}) * 0.1, os = at::rand({3079}) + 0.5;
  const at::Tensor cm = at::rand({2048}) * 0.1, cs = at::rand({2048}) + 0.5;
  net->set_cue_frame(om, os, cm, cs, basis, true);
  EXPECT_TRUE(at::allclose(base, net->encode_conditions((obj - om) / os, (C - cm) / cs), 1e-4, 1e-5));
  config.contact_points = 1025;
  EXPECT_THROW(config.validate(), Error);
}

TEST(Denoiser, FusedSamplingPathEqualsTheModule) {
  // Without autograd in eval mode the encoder runs as ATen's fused layer kernel; with
  // autograd (training) as libtorch's module. Same numbers, paper size included.
  for (const bool paper : {false, true}) {
    torch::manual_seed(6);
    DenoiserConfig c = paper ? DenoiserConfig::paper("motion") : tiny("motion");
    Denoiser net(c);
    net->eval();
    const int T = paper ? 64 : 7;
    const at::Tensor x = at::randn({3, T, c.sample_size}), t = at::tensor({0, 17, 49});
    const at::Tensor obj = at::randn({3, T, c.object_condition_size});
    const at::Tensor module = net->forward(x, t, net->encode_conditions(obj)).detach();
    at::Tensor fused;
    {
      torch::NoGradGuard ng;
      fused = net->forward(x, t, net->encode_conditions(obj));
    }
    EXPECT_LT((fused - module).abs().max().item<float>(), 2e-4 * module.abs().max().item<float>()) << paper;
    EXPECT_GT(module.abs().max().item<float>(), 0.1f);
  }
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
