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

TEST(ContactSupport, BadShapesAreErrors) {
  EXPECT_THROW(hold_contacts(at::zeros({3, 2, 4}), {true, true, true}, {true, true, true}, top_points(), 0.01), Error);
  EXPECT_THROW(hold_contacts(example_maps(), {true}, {true, true, true}, top_points(), 0.01), Error);
  EXPECT_THROW(hold_contacts(example_maps(), {true, true, true}, {true, true, true}, top_points(), 0), Error);
}

}  // namespace
}  // namespace bimart::diffusion
