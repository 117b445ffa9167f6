// Contact support (core/diffusion/contact_support.h): in frames that must be held, the hand
// whose map comes nearest is read as touching; other frames and touching hands are left alone.
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include "core/diffusion/contact_support.h"
#include "core/util/error.h"

namespace bimart::diffusion {
namespace {

// One sample, 3 frames, 4 points (points 0 and 1 on the top part). Left hand 5 cm and more
// away, right hand 8 cm and more; frame 1's right hand touches the bottom (point 3).
at::Tensor example_maps() {
  at::Tensor C = at::empty({1, 3, 2, 4}, at::kFloat);
  for (int t = 0; t < 3; ++t) {
    C[0][t][0] = at::tensor({0.09f, 0.07f, 0.05f, 0.06f});
    C[0][t][1] = at::tensor({0.12f, 0.10f, 0.09f, 0.08f});
  }
  C[0][1][1][3] = 0.002f;
  return C;
}

at::Tensor top_points() { return (at::tensor({1, 1, 0, 0}) > 0).view({1, 4}).expand({3, 4}).contiguous(); }

TEST(ContactSupport, NearestHandTouchesInHeldFramesOnly) {
  const at::Tensor C = example_maps();
  const at::Tensor out = hold_contacts(C, {true, true, false}, {false, false, false}, top_points(), 0.01);
  // Frame 0: nobody touches; the left hand (nearest, 5 cm) is shifted by 5 cm, the right kept.
  EXPECT_TRUE(at::allclose(out[0][0][0], at::tensor({0.04f, 0.02f, 0.0f, 0.01f}), 0, 1e-6));
  EXPECT_TRUE(at::equal(out[0][0][1], C[0][0][1]));
  // Frame 1: the right hand touches already; frame 2 need not be held.
  EXPECT_TRUE(at::equal(out[0][1], C[0][1]));
  EXPECT_TRUE(at::equal(out[0][2], C[0][2]));
}

TEST(ContactSupport, TurningFramesPutTheNearestHandOnTheTopPart) {
  const at::Tensor C = example_maps();
  const at::Tensor out = hold_contacts(C, {false, false, false}, {false, true, false}, top_points(), 0.01);
  // Frame 1: the right hand holds the bottom, nobody the top: the left hand (7 cm from the top
  // part against 10 cm) gets its top entries shifted by 7 cm; its bottom entries stay.
  EXPECT_TRUE(at::allclose(out[0][1][0], at::tensor({0.02f, 0.0f, 0.05f, 0.06f}), 0, 1e-6));
  EXPECT_TRUE(at::equal(out[0][1][1], C[0][1][1]));
  EXPECT_TRUE(at::equal(out[0][0], C[0][0]));
}

TEST(ContactSupport, AroundMotionHoldsBothEndsOfAStep) {
  EXPECT_EQ(around_motion({false, true, false, false}), (std::vector<bool>{false, true, true, false}));
  EXPECT_EQ(around_motion({}), std::vector<bool>{});
}

// Support placement: keypoints [1, 3, 2, 6, 3] and four object points on the x axis (points
// 0 and 1 on the top part, at x = 0 and 0.1; points 2 and 3 at x = 0.5, 0.6). Each hand is a
// row of five keypoints at one height (y) over its point plus one stray keypoint 3.5 cm
// below them: the left hand at 6 cm over point 1, the right at 4 cm over point 3.
struct SupportExample {
  at::Tensor H = at::zeros({1, 3, 2, 6, 3}, at::kFloat);
  at::Tensor P = at::zeros({3, 4, 3}, at::kFloat);
  explicit SupportExample(float stray_drop = 0.035f) {
    for (int t = 0; t < 3; ++t) {
      P[t].select(1, 0) = at::tensor({0.0f, 0.1f, 0.5f, 0.6f});
      const float x[2] = {0.1f, 0.6f}, y[2] = {0.06f, 0.04f};
      for (int h = 0; h < 2; ++h) {
        for (int j = 0; j < 5; ++j) H[0][t][h][j] = at::tensor({x[h], y[h], 0.001f * static_cast<float>(j)});
        H[0][t][h][5] = at::tensor({x[h], y[h] - stray_drop, 0.0f});
      }
    }
  }
};

TEST(ContactSupport, SupportMovesTheNearestHandOntoTheObjectInHeldFramesOnly) {
  const SupportExample e;
  // sigma 0: no smoothing, so each frame's move is exact.
  const at::Tensor d = support_translations(e.H, e.P, {true, false, true}, {false, false, false}, top_points(), 0.01, 0);
  ASSERT_EQ(d.sizes(), (at::IntArrayRef{1, 3, 2, 3}));
  // Held frames: the right hand (4 cm against 6) comes down onto point 3: its row of
  // keypoints moves 4 cm down (the stray keypoint, 5 mm from the object, does not count as
  // touching and ends inside); the left hand stays.
  for (int t : {0, 2}) {
    EXPECT_NEAR(d[0][t][1][1].item<float>(), -0.04f, 1e-6) << "frame " << t;
    EXPECT_NEAR(d[0][t][1][0].item<float>(), 0.0f, 1e-6) << "frame " << t;
    EXPECT_TRUE(at::equal(d[0][t][0], at::zeros({3})));
  }
  EXPECT_TRUE(at::equal(d[0][1], at::zeros({2, 3})));
}

TEST(ContactSupport, SupportPutsAHandOnTheTopPartWhereTheHingeTurns) {
  const SupportExample e;
  const at::Tensor d = support_translations(e.H, e.P, {false, false, false}, {false, true, false}, top_points(), 0.01, 0);
  // Frame 1: nobody on the top part; the left hand is nearest to it (6 cm above point 1).
  EXPECT_NEAR(d[0][1][0][1].item<float>(), -0.06f, 1e-6);
  EXPECT_NEAR(d[0][1][0][0].item<float>(), 0.0f, 1e-6);
  EXPECT_TRUE(at::equal(d[0][1][1], at::zeros({3})));
  // A hand that already touches is left alone: the left hand's row 5 mm above point 1.
  SupportExample near;
  near.H.select(4, 1) -= 0.055;
  const at::Tensor none = support_translations(near.H, near.P, {true, true, true}, {true, true, true}, top_points(), 0.01, 0);
  EXPECT_TRUE(at::equal(none, at::zeros_like(none)));
}

TEST(ContactSupport, SmoothedSupportStillReachesInsideAStretch) {
  // Five held frames in a row (sigma 2): the rounds make up what the smoothing takes, so
  // every frame ends with the hand's row of keypoints within reach of the object.
  SupportExample e(0.0f);
  at::Tensor H = e.H.repeat({1, 2, 1, 1, 1}).slice(1, 0, 5).contiguous();
  at::Tensor P = e.P.repeat({2, 1, 1}).slice(0, 0, 5).contiguous();
  for (int t = 0; t < 5; ++t) H[0][t].select(2, 1) += 0.01f * static_cast<float>(t);  // rising away
  const at::Tensor top = top_points()[0].expand({5, 4});
  const at::Tensor d = support_translations(H, P, std::vector<bool>(5, true), std::vector<bool>(5, false), top, 0.01, 2.0);
  const at::Tensor moved = H + d.unsqueeze(3);
  for (int t = 0; t < 5; ++t) {
    const float gap = (moved[0][t][1][0] - P[t][3]).norm().item<float>();  // the row's first keypoint
    EXPECT_LT(gap, 0.01f) << "frame " << t;
  }
}

TEST(ContactSupport, BadShapesAreErrors) {
  EXPECT_THROW(hold_contacts(at::zeros({3, 2, 4}), {true, true, true}, {true, true, true}, top_points(), 0.01), Error);
  EXPECT_THROW(hold_contacts(example_maps(), {true}, {true, true, true}, top_points(), 0.01), Error);
  EXPECT_THROW(hold_contacts(example_maps(), {true, true, true}, {true, true, true}, top_points(), 0), Error);
  const SupportExample e;
  EXPECT_THROW(support_translations(e.H, e.P, {true}, {true, true, true}, top_points(), 0.01, 2), Error);
  EXPECT_THROW(support_translations(e.H[0], e.P, {true, true, true}, {true, true, true}, top_points(), 0.01, 2), Error);
  EXPECT_THROW(support_translations(e.H, e.P, {true, true, true}, {true, true, true}, top_points(), 0, 2), Error);
}

}  // namespace
}  // namespace bimart::diffusion
