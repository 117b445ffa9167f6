// refine.mano_fit's solver (core/refine/mano_fit.h): keypoints posed from known θ, β plus
// 2 mm noise are fitted back to the hand they came from.
#include "core/refine/mano_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <ATen/ATen.h>

#include "core/refine/hand_state.h"
#include "core/util/error.h"
#include "tests/refine/known_motion.h"
#include "tests/synth/shipped_hands.h"

namespace bimart {
namespace {

TEST(ManoFit, RecoversAKnownMotionFromNoisyKeypoints) {
  const auto& models = test::shipped_hands();
  const int N = 24;
  const HandMotion truth = test::known_motion(models, N, /*seed=*/3);
  const at::Tensor H = test::noisy_keypoints(models, truth, /*sigma_mm=*/2.0, /*seed=*/4);

  ManoFitReport report;
  const HandMotion fit = fit_mano(models, H, {}, &report);
  ASSERT_TRUE(fit.has_vertices());
  const double err = (fit.vertices - truth.vertices).norm(2, {3}).mean().item<double>();
  EXPECT_LT(err, 0.003) << "mean vertex error " << err * 1000 << " mm";
  for (int h = 0; h < 2; ++h) {
    // 2 mm per axis of noise, about 3.5 mm per keypoint: the fit cannot be far closer.
    EXPECT_LT(report.hands[h].mean_keypoint_error, 0.004);
    EXPECT_GT(report.hands[h].mean_keypoint_error, 0.0015);
    EXPECT_LT(report.hands[h].final_cost, report.hands[h].initial_cost);
  }
}

TEST(ManoFit, ExactKeypointsFitToWellUnderAMillimetre) {
  const auto& models = test::shipped_hands();
  const HandMotion truth = test::known_motion(models, 8, /*seed=*/11);
  const at::Tensor H = test::noisy_keypoints(models, truth, 0.0, 0);
  ManoFitReport r;
  const HandMotion fit = fit_mano(models, H, {}, &r);
  for (int h = 0; h < 2; ++h)
    printf("hand %d: cost %g -> %g in %d iterations, kp err %.3f mm, %.3f s\n", h, r.hands[h].initial_cost,
           r.hands[h].final_cost, r.hands[h].iterations, r.hands[h].mean_keypoint_error * 1000, r.hands[h].seconds);
  EXPECT_LT((fit.vertices - truth.vertices).norm(2, {3}).mean().item<double>(), 0.0005);
}

TEST(ManoFit, RejectsBadInput) {
  const auto& models = test::shipped_hands();
  EXPECT_THROW(fit_mano(models, at::zeros({2, 4, 99, 3})), Error);
  at::Tensor H = at::zeros({2, 4, 100, 3});
  H[0][1][2][0] = NAN;
  EXPECT_THROW(fit_mano(models, H), Error);
  ManoFitOptions bad;
  bad.w_smooth = -1;
  EXPECT_THROW(fit_mano(models, at::zeros({2, 4, 100, 3}), bad), Error);
}

}  // namespace
}  // namespace bimart
