// The contact cue: analytic centroids, spreads, counts and distances; the object points of
// the BPS features are the encoder's hit vertices; bad shapes are errors.
#include "core/features/contact_cue.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"

namespace bimart {
namespace {

// Entry of the cue of hand h: temperature k (0: 1 cm, 1: 3 cm, 2: 10 cm), field f (0-2 μ,
// 3-8 covariance xx yy zz xy xz yz, 9 log count / 3); f = -1 is d_min.
double cue_at(const at::Tensor& cue, int h, int k, int f) {
  const int i = h * kContactCuePerHand + (f < 0 ? 3 * 10 : k * 10 + f);
  return cue.flatten()[i].item<double>();
}

TEST(ContactCue, NearestPointsAtTheTightestTemperature) {
  // Four object points; the left hand is 1 cm from p0 and far from the others; the right
  // hand is equally near p1 and p2 (4 cm), which lie 10 cm apart on x.
  const at::Tensor p = at::tensor({0.0, 0.0, 0.0, 0.3, 0.0, 0.0, 0.4, 0.0, 0.0, 0.0, 0.5, 0.0}, at::kDouble).view({4, 3});
  const at::Tensor c = at::tensor({0.01, 0.31, 0.41, 0.5, 0.5, 0.04, 0.04, 0.6}, at::kDouble).view({2, 4});
  const at::Tensor cue = contact_cue(p, c);
  ASSERT_EQ(cue.sizes(), (at::IntArrayRef{kContactCueSize}));
  // Left, σ = 1 cm: all weight on p0 (the next is e^-30 behind).
  for (int f = 0; f < 9; ++f) EXPECT_NEAR(cue_at(cue, 0, 0, f), 0.0, 1e-6) << f;
  EXPECT_NEAR(cue_at(cue, 0, 0, 9), 0.0, 1e-6);        // one point: log 1
  EXPECT_NEAR(cue_at(cue, 0, 0, -1), 0.1, 1e-6);       // d_min 1 cm = 0.1 dm
  // Right: the midpoint of p1 and p2 (3.5 dm), variance (0.5 dm)² on x, two points.
  EXPECT_NEAR(cue_at(cue, 1, 0, 0), 3.5, 1e-5);
  EXPECT_NEAR(cue_at(cue, 1, 0, 1), 0.0, 1e-5);
  EXPECT_NEAR(cue_at(cue, 1, 0, 3), 0.25, 1e-4);
  EXPECT_NEAR(cue_at(cue, 1, 0, 4), 0.0, 1e-5);
  EXPECT_NEAR(cue_at(cue, 1, 0, 9), std::log(2.0) / 3.0, 1e-5);
  EXPECT_NEAR(cue_at(cue, 1, 0, -1), 0.4, 1e-6);
  // At 10 cm the left hand's weights spread: w ∝ exp(-d / 1 dm) over the four points.
  const double w[4] = {std::exp(-0.1), std::exp(-3.1), std::exp(-4.1), std::exp(-5.0)};
  const double sum = w[0] + w[1] + w[2] + w[3];
  EXPECT_NEAR(cue_at(cue, 0, 2, 0), (3.0 * w[1] + 4.0 * w[2]) / sum, 1e-5);
  EXPECT_NEAR(cue_at(cue, 0, 2, 1), 5.0 * w[3] / sum, 1e-5);
}

TEST(ContactCue, BatchDimensionsAreKept) {
  at::manual_seed(1);
  const at::Tensor p = at::rand({3, 5, 1024, 3}), c = at::rand({3, 5, 2, 1024});
  const at::Tensor cue = contact_cue(p, c);
  ASSERT_EQ(cue.sizes(), (at::IntArrayRef{3, 5, kContactCueSize}));
  EXPECT_TRUE(at::allclose(cue[2][4], contact_cue(p[2][4], c[2][4]), 1e-5, 1e-6));
}

TEST(ContactCue, ObjectPointsUndoTheEncoderSpace) {
  const at::Tensor basis = at::rand({1024, 3}), hit = at::rand({2, 1024, 3});
  const at::Tensor scale = at::tensor({2.0f, 4.0f});
  const at::Tensor p = object_points_from_bps(hit - basis, basis, scale);
  EXPECT_TRUE(at::allclose(p[0], hit[0] / 2.0));
  EXPECT_TRUE(at::allclose(p[1], hit[1] / 4.0));
  EXPECT_TRUE(at::allclose(object_points_from_bps(hit - basis, basis, at::scalar_tensor(1.0f)), hit));
}

TEST(ContactCue, BadShapesAreClearErrors) {
  EXPECT_THROW(contact_cue(at::zeros({1024, 3}), at::zeros({1024})), Error);
  EXPECT_THROW(contact_cue(at::zeros({1024, 3}), at::zeros({2, 1000})), Error);
  EXPECT_THROW(contact_cue(at::zeros({4, 1024, 3}), at::zeros({5, 2, 1024})), Error);
  EXPECT_THROW(object_points_from_bps(at::zeros({4, 1024, 3}), at::zeros({512, 3}), at::ones({4})), Error);
}

}  // namespace
}  // namespace bimart
