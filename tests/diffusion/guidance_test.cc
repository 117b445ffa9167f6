// Contact-map guidance: the implied map against brute force, the analytic gradient against
// autograd, and repeated corrections lower the discrepancy of a fixed example.
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include "core/diffusion/contact_guidance.h"

namespace bimart::diffusion {
namespace {

struct Example {
  at::Tensor points, truth, start;  // [T, 1024, 3], X [1, T, 1200] of the "true" hands, and a guess
};

Example example(int T) {
  at::manual_seed(5);
  Example e;
  e.points = at::rand({T, 1024, 3}) * 0.2 - 0.1;  // a 20 cm cube of object points
  const at::Tensor H = at::rand({1, T, 2, 100, 3}) * 0.2 - 0.1;
  e.truth = at::cat({H.reshape({1, T, 600}), at::zeros({1, T, 600})}, -1);
  e.start = e.truth.clone();
  e.start.slice(-1, 0, 600) += at::randn({1, T, 600}) * 0.02;
  return e;
}

TEST(ContactGuidance, ImpliedMapIsTheBruteForceMinimum) {
  const Example e = example(3);
  const at::Tensor H = e.truth.slice(-1, 0, 600).reshape({1, 3, 2, 100, 3});
  const auto [map, idx] = ContactMapGuidance::keypoint_contact_map(H, e.points);
  ASSERT_EQ(map.sizes(), (std::vector<int64_t>{1, 3, 2, 1024}));
  for (int t = 0; t < 3; ++t)
    for (int h = 0; h < 2; ++h) {
      const at::Tensor d = at::cdist(e.points[t], H[0][t][h]);  // [1024, 100]
      EXPECT_TRUE(at::allclose(map[0][t][h], std::get<0>(d.min(1)), 1e-5, 1e-5));
    }
}

TEST(ContactGuidance, CorrectionIsMinusTheNormalisedAutogradGradient) {
  const Example e = example(4);
  const at::Tensor target = std::get<0>(ContactMapGuidance::keypoint_contact_map(
      e.truth.slice(-1, 0, 600).reshape({1, 4, 2, 100, 3}), e.points))[0];
  const ContactMapGuidance g(e.points, target, 1.0);
  const at::Tensor corr = g.correction(e.start, 0, 10, 50);
  // Autograd of the same loss (min over keypoints of the pairwise distances).
  at::Tensor H = e.start.slice(-1, 0, 600).clone().requires_grad_(true);
  const at::Tensor d = at::cdist(e.points.unsqueeze(1).expand({4, 2, 1024, 3}), H.reshape({4, 2, 100, 3}));
  const at::Tensor loss = (std::get<0>(d.min(-1)) - target).pow(2).mean();
  loss.backward();
  const at::Tensor grad = H.grad().reshape({1, 4, 600});
  const at::Tensor expected = -grad / grad.norm();
  EXPECT_TRUE(at::allclose(corr.slice(-1, 0, 600), expected, 1e-3, 1e-5))
      << (corr.slice(-1, 0, 600) - expected).abs().max().item<double>();
  EXPECT_NEAR(corr.slice(-1, 0, 600).norm().item<double>(), 1.0, 1e-5);
  EXPECT_TRUE(at::allclose(corr.slice(-1, 600, 1200), -corr.slice(-1, 0, 600)));  // H + D kept
}

TEST(ContactGuidance, LowersTheDiscrepancyOfAFixedExample) {
  const Example e = example(8);
  const at::Tensor target = std::get<0>(ContactMapGuidance::keypoint_contact_map(
      e.truth.slice(-1, 0, 600).reshape({1, 8, 2, 100, 3}), e.points))[0];
  const ContactMapGuidance g(e.points, target, 0.01);
  at::Tensor x = e.start.clone();
  const double before = g.discrepancy(x, 0).item<double>();
  for (int i = 0; i < 30; ++i) x = x + g.correction(x, 0, 0, 50);
  const double after = g.discrepancy(x, 0).item<double>();
  EXPECT_LT(after, 0.6 * before) << before << " -> " << after;
  // A window later in the sequence uses its own frames.
  const ContactMapGuidance g2(at::cat({e.points, e.points}), at::cat({target, target}), 0.01);
  EXPECT_TRUE(at::allclose(g2.correction(e.start, 8, 0, 50), g.correction(e.start, 0, 0, 50)));
  EXPECT_THROW(g.correction(e.start, 1, 0, 50), std::exception);  // frames 1..9 of 8
}

TEST(ContactGuidance, ReleasedLastStepsTakeNoCorrection) {
  const Example e = example(4);
  const at::Tensor target = std::get<0>(ContactMapGuidance::keypoint_contact_map(
      e.truth.slice(-1, 0, 600).reshape({1, 4, 2, 100, 3}), e.points))[0];
  ContactMapGuidance g(e.points, target, 1.0);
  const at::Tensor full = g.correction(e.start, 0, 2, 50);
  g.set_release(3);
  EXPECT_EQ(g.correction(e.start, 0, 2, 50).abs().max().item<double>(), 0.0);  // t = 2 < 3: released
  EXPECT_EQ(g.correction(e.start, 0, 0, 50).abs().max().item<double>(), 0.0);
  EXPECT_TRUE(at::equal(g.correction(e.start, 0, 3, 50), full));  // t = 3: guided as before
  EXPECT_NEAR(full.slice(-1, 0, 600).norm().item<double>(), 1.0, 1e-5);
  EXPECT_THROW(g.set_release(-1), std::exception);
}

}  // namespace
}  // namespace bimart::diffusion
