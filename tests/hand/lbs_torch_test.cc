#include "core/hand/lbs_torch.h"

#include <ceres/jet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include "core/hand/lbs.h"
#include "tests/hand/synthetic_model.h"

namespace bimart {
namespace {

using ::testing::HasSubstr;

struct Batch {
  at::Tensor rot, pose, trans, betas;
};

Batch random_batch(int64_t B, at::ScalarType dtype, uint64_t seed) {
  at::manual_seed(seed);
  const auto o = at::TensorOptions().dtype(dtype);
  return {0.6 * (2 * at::rand({B, 3}, o) - 1), 0.6 * (2 * at::rand({B, 45}, o) - 1),
          0.3 * (2 * at::rand({B, 3}, o) - 1), 2.0 * (2 * at::rand({B, 10}, o) - 1)};
}

LbsResult<double> templated(const HandModel& m, const Batch& b, int64_t i) {
  const at::Tensor r = b.rot[i].contiguous(), p = b.pose[i].contiguous(),
                   t = b.trans[i].contiguous(), s = b.betas[i].contiguous();
  LbsResult<double> out;
  lbs(m, r.data_ptr<double>(), p.data_ptr<double>(), t.data_ptr<double>(), s.data_ptr<double>(), &out);
  return out;
}

double max_diff(const at::Tensor& t, const double* ref, int64_t n) {
  const at::Tensor c = t.to(at::kDouble).contiguous();
  double worst = 0;
  for (int64_t i = 0; i < n; ++i) worst = std::max(worst, std::abs(c.data_ptr<double>()[i] - ref[i]));
  return worst;
}

TEST(LbsTorchTest, Float64MatchesTheTemplatedVersion) {
  const HandModel m = testing::make_synthetic_hand(50);
  const HandModelTensors mt = HandModelTensors::from(m, at::kDouble);
  const Batch b = random_batch(8, at::kDouble, 11);
  const LbsTensors out = lbs(mt, b.rot, b.pose, b.trans, b.betas);
  ASSERT_EQ(out.vertices.sizes(), (std::vector<int64_t>{8, 50, 3}));
  ASSERT_EQ(out.joints.sizes(), (std::vector<int64_t>{8, 16, 3}));
  for (int64_t i = 0; i < 8; ++i) {
    const LbsResult<double> r = templated(m, b, i);
    EXPECT_LT(max_diff(out.vertices[i], r.vertices.data(), 150), 1e-12) << "hand " << i;
    EXPECT_LT(max_diff(out.joints[i], r.joints.data(), 48), 1e-12) << "hand " << i;
  }
  // float32: the same to single-precision rounding (well under 0.1 mm).
  const HandModelTensors mf = HandModelTensors::from(m, at::kFloat);
  const LbsTensors of = lbs(mf, b.rot.to(at::kFloat), b.pose.to(at::kFloat), b.trans.to(at::kFloat),
                            b.betas.to(at::kFloat));
  EXPECT_EQ(of.vertices.scalar_type(), at::kFloat);
  EXPECT_LT((of.vertices.to(at::kDouble) - out.vertices).abs().max().item<double>(), 1e-5);
}

TEST(LbsTorchTest, ZeroInputsReproduceTheTemplate) {
  const HandModel m = testing::make_synthetic_hand(50);
  const HandModelTensors mt = HandModelTensors::from(m, at::kDouble);
  const auto o = at::TensorOptions().dtype(at::kDouble);
  const LbsTensors out =
      lbs(mt, at::zeros({2, 3}, o), at::zeros({2, 45}, o), at::zeros({2, 3}, o), at::zeros({2, 10}, o));
  for (int64_t i = 0; i < 2; ++i) EXPECT_LT(max_diff(out.vertices[i], m.v_template.data(), 150), 1e-15);
}

TEST(LbsTorchTest, Keypoints21AreJointsThenFingertips) {
  const HandModel m = testing::make_synthetic_hand(50);
  const HandModelTensors mt = HandModelTensors::from(m, at::kDouble);
  const Batch b = random_batch(3, at::kDouble, 12);
  const LbsTensors out = lbs(mt, b.rot, b.pose, b.trans, b.betas);
  const at::Tensor k = keypoints21(mt, out);
  ASSERT_EQ(k.sizes(), (std::vector<int64_t>{3, 21, 3}));
  EXPECT_TRUE(at::equal(k.slice(1, 0, 16), out.joints));
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(at::equal(k.select(1, 16 + i), out.vertices.select(1, m.fingertips[i])));
}

// Autograd of a weighted sum of vertices equals the Jet gradient of the templated version,
// also at the zero pose.
TEST(LbsTorchTest, AutogradMatchesJetGradients) {
  using Jet = ceres::Jet<double, 61>;
  const HandModel m = testing::make_synthetic_hand(30);
  const HandModelTensors mt = HandModelTensors::from(m, at::kDouble);
  Batch b = random_batch(2, at::kDouble, 13);
  b.rot[1].zero_();
  b.pose[1].zero_();
  at::manual_seed(14);
  const at::Tensor c = at::randn({2, 30, 3}, at::kDouble);
  at::Tensor x = at::cat({b.rot, b.pose, b.trans, b.betas}, 1).detach().requires_grad_(true);
  const LbsTensors out = lbs(mt, x.slice(1, 0, 3), x.slice(1, 3, 48), x.slice(1, 48, 51), x.slice(1, 51, 61));
  const at::Tensor loss = (out.vertices * c).sum();
  loss.backward();
  const at::Tensor grad = x.grad();
  ASSERT_TRUE(grad.isfinite().all().item<bool>());
  for (int64_t i = 0; i < 2; ++i) {
    std::vector<Jet> xj(61);
    for (int k = 0; k < 61; ++k) xj[k] = Jet(x[i][k].item<double>(), k);
    LbsResult<Jet> r;
    lbs(m, &xj[0], &xj[3], &xj[48], &xj[51], &r);
    Jet sum(0.0);
    for (int v = 0; v < 30; ++v)
      for (int d = 0; d < 3; ++d) sum += c[i][v][d].item<double>() * r.vertices(v, d);
    for (int k = 0; k < 61; ++k) EXPECT_NEAR(grad[i][k].item<double>(), sum.v[k], 1e-11) << i << " " << k;
  }
}

TEST(LbsTorchTest, RefusesWrongShapesAndTypes) {
  const HandModelTensors mt = HandModelTensors::from(testing::make_synthetic_hand(20), at::kFloat);
  const Batch b = random_batch(4, at::kFloat, 15);
  auto message = [&](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_THAT(message([&] { lbs(mt, b.rot, b.pose.slice(1, 0, 44), b.trans, b.betas); }),
              HasSubstr("lbs: pose must be [4, 45], got [4, 44]"));
  EXPECT_THAT(message([&] { lbs(mt, b.rot, b.pose, b.trans, b.betas.to(at::kDouble)); }),
              HasSubstr("lbs: betas has dtype Double"));
}

}  // namespace
}  // namespace bimart
