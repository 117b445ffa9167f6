// Contact placement (core/diffusion/contact_placement.h): a hand hovering off the contacts
// its map marks is translated back onto them; frames without contacts are left alone.
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include <cmath>

#include "core/diffusion/contact_guidance.h"
#include "core/diffusion/contact_placement.h"
#include "core/util/error.h"

namespace bimart::diffusion {
namespace {

// 1024 points on a sphere of radius 6 cm about the origin (a Fibonacci lattice).
at::Tensor sphere_points() {
  at::Tensor p = at::empty({1024, 3}, at::kFloat);
  const double golden = M_PI * (3 - std::sqrt(5.0));
  for (int i = 0; i < 1024; ++i) {
    const double y = 1 - 2 * (i + 0.5) / 1024, r = std::sqrt(1 - y * y);
    p[i][0] = 0.06 * r * std::cos(golden * i);
    p[i][1] = 0.06 * y;
    p[i][2] = 0.06 * r * std::sin(golden * i);
  }
  return p;
}

// A "hand": 100 keypoints in a curved 8 × 8 cm patch that wraps the sphere at +x, 2 mm off it.
at::Tensor wrapping_hand() {
  at::Tensor h = at::empty({100, 3}, at::kFloat);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const double a = (i - 4.5) * 0.08, b = (j - 4.5) * 0.08;  // radians over the sphere
      h[i * 10 + j][0] = 0.062 * std::cos(a) * std::cos(b);
      h[i * 10 + j][1] = 0.062 * std::sin(a);
      h[i * 10 + j][2] = 0.062 * std::cos(a) * std::sin(b);
    }
  return h;
}

TEST(ContactPlacement, TranslatesAHoveringHandBackOntoItsContacts) {
  const int T = 5;
  const at::Tensor P = sphere_points().unsqueeze(0).expand({T, 1024, 3}).contiguous();
  const at::Tensor truth = wrapping_hand().view({1, 1, 1, 100, 3}).expand({1, T, 2, 100, 3}).contiguous();
  const at::Tensor C = ContactMapGuidance::keypoint_contact_map(truth, P).first;  // [1, T, 2, 1024]
  // Both hands hover: 3 cm out along +x and 1 cm sideways, the second hand 2 cm up as well.
  at::Tensor offset = at::zeros({1, T, 2, 1, 3});
  offset.select(2, 0).select(-1, 0).fill_(0.03);
  offset.select(2, 0).select(-1, 2).fill_(0.01);
  offset.select(2, 1).select(-1, 0).fill_(0.03);
  offset.select(2, 1).select(-1, 1).fill_(0.02);
  PlacementOptions o;
  o.iterations = 30;
  const at::Tensor delta = contact_translations(truth + offset, P, C, o);  // [1, T, 2, 3]
  ASSERT_EQ(delta.sizes(), (std::vector<int64_t>{1, T, 2, 3}));
  const double error = (delta + offset.squeeze(3)).norm(2, -1).max().item<double>();
  EXPECT_LT(error, 0.004) << delta[0][0];
  // Placed, the map implied by the keypoints is close to the target again.
  const at::Tensor placed = truth + offset + delta.unsqueeze(3);
  const at::Tensor before = (ContactMapGuidance::keypoint_contact_map(truth + offset, P).first - C).abs().mean();
  const at::Tensor after = (ContactMapGuidance::keypoint_contact_map(placed, P).first - C).abs().mean();
  EXPECT_LT(after.item<double>(), 0.2 * before.item<double>());
}

TEST(ContactPlacement, DepthPlacesTheHandThatMuchCloser) {
  const int T = 3;
  const at::Tensor P = sphere_points().unsqueeze(0).expand({T, 1024, 3}).contiguous();
  const at::Tensor truth = wrapping_hand().view({1, 1, 1, 100, 3}).expand({1, T, 2, 100, 3}).contiguous();
  const at::Tensor C = ContactMapGuidance::keypoint_contact_map(truth, P).first;
  PlacementOptions o;
  o.iterations = 30;
  o.depth = 0.002;  // the hand wraps the sphere at 2 mm: placed 2 mm deeper, it moves ~2 mm towards -x
  const at::Tensor delta = contact_translations(truth, P, C, o);
  EXPECT_NEAR(delta.select(-1, 0).mean().item<double>(), -0.002, 0.0008) << delta[0][0];
  EXPECT_LT(delta.select(-1, 1).abs().max().item<double>(), 0.0005);
  o.depth = std::nan("");
  EXPECT_THROW(contact_translations(truth, P, C, o), Error);
}

TEST(ContactPlacement, FramesWithoutContactsStayAndTheTranslationFadesIntoThem) {
  const int T = 40;
  const at::Tensor P = sphere_points().unsqueeze(0).expand({T, 1024, 3}).contiguous();
  const at::Tensor truth = wrapping_hand().view({1, 1, 1, 100, 3}).expand({1, T, 2, 100, 3}).contiguous();
  at::Tensor C = ContactMapGuidance::keypoint_contact_map(truth, P).first.clone();
  C.slice(1, 20, T).fill_(1.0);  // no contact from frame 20 on
  at::Tensor offset = at::zeros({1, T, 2, 1, 3});
  offset.select(-1, 0).fill_(0.02);
  PlacementOptions o;
  o.sigma = 2;
  const at::Tensor delta = contact_translations(truth + offset, P, C, o);
  const at::Tensor size = delta.norm(2, -1)[0].select(1, 0);  // [T], first hand
  EXPECT_NEAR(size[5].item<double>(), 0.02, 0.004);           // inside the contacts: placed
  EXPECT_LT(size[25].item<double>(), 1e-3);                   // 3 sigma after: nearly untouched
  EXPECT_LT(size[39].item<double>(), 1e-9);
  // Fading, not a jump. Frame 21 still has Gaussian weight > 1 from frames < 20 (the
  // normaliser's clamp), so it keeps the full step; frame 22 has ~0.52 of it.
  EXPECT_LT(size[22].item<double>(), 0.75 * size[18].item<double>());
  EXPECT_GT(size[22].item<double>(), 0.25 * size[18].item<double>());
}

TEST(ContactPlacement, SnapPlacesANearlyTouchingHandWhereItsMapIsSmallest) {
  const int T = 3;
  const at::Tensor P = sphere_points().unsqueeze(0).expand({T, 1024, 3}).contiguous();
  const at::Tensor truth = wrapping_hand().view({1, 1, 1, 100, 3}).expand({1, T, 2, 100, 3}).contiguous();
  // A blurred map: every distance 2 cm too large, so no point is below the 1 cm threshold.
  const at::Tensor C = ContactMapGuidance::keypoint_contact_map(truth, P).first + 0.02;
  at::Tensor offset = at::zeros({1, T, 2, 1, 3});
  offset.select(-1, 0).fill_(0.03);
  PlacementOptions o;
  o.iterations = 30;
  EXPECT_EQ(contact_translations(truth + offset, P, C, o).abs().max().item<double>(), 0.0);  // no contacts
  o.snap = 0.03;
  const at::Tensor delta = contact_translations(truth + offset, P, C, o);
  EXPECT_LT((delta + offset.squeeze(3)).norm(2, -1).max().item<double>(), 0.004);
  o.snap = 0.015;  // the minimum (~2 cm) is beyond the snap distance
  EXPECT_EQ(contact_translations(truth + offset, P, C, o).abs().max().item<double>(), 0.0);
}

TEST(ContactPlacement, GuidancePlacesOnlyAtItsLastSteps) {
  const int T = 4;
  const at::Tensor P = sphere_points().unsqueeze(0).expand({T, 1024, 3}).contiguous();
  const at::Tensor truth = wrapping_hand().view({1, 1, 1, 100, 3}).expand({1, T, 2, 100, 3}).contiguous();
  const at::Tensor C = ContactMapGuidance::keypoint_contact_map(truth, P).first[0];  // [T, 2, 1024]
  at::Tensor x0 = at::zeros({1, T, 1200});
  x0.slice(-1, 0, 600).copy_((truth + 0.02).reshape({1, T, 600}));
  ContactMapGuidance g(P, C, 0.0);
  g.set_placement(3);
  EXPECT_FALSE(g.placement(x0, 0, 3, 50).defined());  // step 3: not yet
  EXPECT_EQ(g.correction(x0, 0, 2, 50).abs().max().item<double>(), 0.0);  // scale 0: no gradient step
  const at::Tensor c = g.placement(x0, 0, 2, 50);
  EXPECT_GT(c.abs().max().item<double>(), 0.01);
  // H moves, and D by the opposite: H + D stays.
  EXPECT_TRUE(at::allclose(c.slice(-1, 0, 600), -c.slice(-1, 600, 1200)));
  EXPECT_LT(g.discrepancy(x0 + c, 0).item<double>(), 0.1 * g.discrepancy(x0, 0).item<double>());
  EXPECT_THROW(g.set_placement(-1), Error);
  PlacementOptions bad;
  bad.threshold = 0;
  EXPECT_THROW(g.set_placement(1, bad), Error);
}

}  // namespace
}  // namespace bimart::diffusion
