// refine.mano_fit's solver (core/refine/mano_fit.h): keypoints posed from known θ, β plus
// 2 mm noise are fitted back to the hand they came from.
#include "core/refine/mano_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <ATen/ATen.h>

#include "core/metrics/hand_plausibility.h"
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

// Keypoints of hands whose index and middle fingers are bent 70° backwards at the PIP and
// twisted 40° at the MCP (a diffusion model's worst): the fit keeps every joint within its
// anatomical range; without the limits it follows the keypoints out of them.
TEST(ManoFit, KeepsEveryJointWithinItsRangeOnCorruptedKeypoints) {
  const auto& models = test::shipped_hands();
  const int N = 6;
  HandMotion bent = test::known_motion(models, N, /*seed=*/5);
  for (int h = 0; h < 2; ++h) {
    const JointLimits L(*models[h]);
    at::Tensor pose = bent.hands[h].pose.to(at::kDouble).contiguous();
    for (int t = 0; t < N; ++t)
      for (int finger : {0, 1}) {
        double* p = pose[t].data_ptr<double>() + 9 * finger;
        const Eigen::Vector3d pip_axis = Eigen::Vector3d(p[3], p[4], p[5]).normalized();  // mostly flexion
        for (int k = 0; k < 3; ++k) p[3 + k] = -70.0 * M_PI / 180 * pip_axis[k];
        p[0] += 0.7;  // about 40° more about x: a twist and a sideways bend at the MCP
      }
    bent.hands[h].pose = pose.to(at::kFloat);
  }
  bent.vertices = pose_hand_vertices(models, bent);
  const at::Tensor H = test::noisy_keypoints(models, bent, 0.0, 0);
  const auto worst = [&](const HandMotion& m) { return test::largest_joint_excess(models, m); };
  EXPECT_GT(worst(bent), 40.0);
  EXPECT_LT(worst(fit_mano(models, H)), 1e-3);  // degrees; the motion's poses are float32
  ManoFitOptions off;
  off.w_limits = 0;
  EXPECT_GT(worst(fit_mano(models, H, off)), 20.0);
}

// The largest finger-order shortfall (core/hand/finger_order.h, m) over a motion's hands
// and frames: > 0 where neighbouring fingers are closer across the hand than the gap or
// crossed.
double worst_finger_shortfall(const std::array<const HandModel*, 2>& models, const HandMotion& m, double gap) {
  const PosedHands p = pose_hands(models, m);
  const at::Tensor J = p.joints.to(at::kDouble).contiguous(), V = p.vertices.to(at::kDouble).contiguous();
  double worst = -1;
  for (int h = 0; h < 2; ++h)
    for (int64_t t = 0; t < J.size(1); ++t) {
      double joints[16][3], tips[5][3], r[kFingerOrderResiduals];
      for (int j = 0; j < 16; ++j)
        for (int k = 0; k < 3; ++k) joints[j][k] = J[h][t][j][k].item<double>();
      for (int f = 0; f < 5; ++f)
        for (int k = 0; k < 3; ++k) tips[f][k] = V[h][t][models[h]->fingertips[f]][k].item<double>();
      finger_order_shortfall<double>(joints, tips, gap, r);
      for (double v : r) worst = std::max(worst, v);
    }
  return worst;
}

// Keypoints whose index finger lies on the middle finger (its middle and last phalanges
// moved 24 mm across the hand, as a diffusion model's blurred fingers come): without the
// finger-order term the fit crosses the two fingers, with it they stay side by side.
TEST(ManoFit, KeepsTheFingersSideBySideOnOverlappingKeypoints) {
  const auto& models = test::shipped_hands();
  const int N = 6;
  const HandMotion truth = test::known_motion(models, N, /*seed=*/7);
  EXPECT_LT(worst_finger_shortfall(models, truth, kFingerGap), 0.0) << "the known motion keeps the gap";
  const at::Tensor H = test::merged_keypoints(models, truth, 0.024);  // onto the middle finger
  ManoFitOptions off;
  const double crossed = worst_finger_shortfall(models, fit_mano(models, H.to(at::kFloat), off), kFingerGap);
  ManoFitOptions on;
  on.w_fingers = 100;
  const double kept = worst_finger_shortfall(models, fit_mano(models, H.to(at::kFloat), on), kFingerGap);
  std::printf("largest shortfall: %.1f mm without the term, %.1f mm with it\n", crossed * 1000, kept * 1000);
  EXPECT_GT(crossed, kFingerGap);  // past each other
  EXPECT_LT(kept, 0.001);
}

// Keypoints whose index finger lies half-way onto the middle finger (moved 12 mm across the
// hand, as a diffusion model's blurred fingers come): the fit puts the two fingers' bones
// closer than the plausibility measure allows; with the separation term they keep its gap.
TEST(ManoFit, KeepsTwoFingersApartOnMergedKeypoints) {
  const auto& models = test::shipped_hands();
  const int N = 6;
  const HandMotion truth = test::known_motion(models, N, /*seed=*/7);
  EXPECT_GT(test::closest_fingers(models, truth), kCrossedGap) << "the known motion is plausible";
  const at::Tensor H = test::merged_keypoints(models, truth, 0.012);
  ManoFitOptions off;
  off.w_separation = 0;
  const double merged = test::closest_fingers(models, fit_mano(models, H.to(at::kFloat), off));
  const ManoFitOptions on;  // the default holds them apart
  const double apart = test::closest_fingers(models, fit_mano(models, H.to(at::kFloat), on));
  std::printf("closest fingers: %.1f mm without the term, %.1f mm with it\n", merged * 1000, apart * 1000);
  EXPECT_LT(merged, kCrossedGap);
  EXPECT_GT(apart, kFingerSeparation - 0.001);
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
  bad.w_smooth = 0;
  bad.w_limits = -1;
  EXPECT_THROW(fit_mano(models, at::zeros({2, 4, 100, 3}), bad), Error);
}

}  // namespace
}  // namespace bimart
