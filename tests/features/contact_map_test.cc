#include "core/features/contact_map.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include "core/features/bps.h"
#include "core/features/contact_cue.h"
#include "core/object/families/families.h"
#include "core/object/object_state.h"
#include "core/util/data_path.h"
#include "core/util/error.h"

namespace bimart {
namespace {

TEST(ContactMap, AnalyticDistances) {
  // Two object points; the left hand has points at distance 0.03 and 0.05 from the first,
  // the right hand sits 0.2 above the second.
  at::Tensor obj = at::zeros({1, 2, 3}, at::kDouble);
  obj[0][1][0] = 1.0;
  at::Tensor hands = at::zeros({2, 1, 2, 3}, at::kDouble);
  hands[0][0][0][1] = 0.03;
  hands[0][0][1][2] = -0.05;
  hands[1][0][0] = at::tensor({1.0, 0.0, 0.2}, at::kDouble);
  hands[1][0][1] = at::tensor({1.0, 0.5, 0.0}, at::kDouble);
  const at::Tensor c = contact_maps(obj, hands);
  ASSERT_EQ(c.sizes(), (at::IntArrayRef{1, 2, 2}));
  EXPECT_NEAR(c[0][0][0].item<double>(), 0.03, 1e-15);
  EXPECT_NEAR(c[0][0][1].item<double>(), std::sqrt(1.0 + 0.03 * 0.03), 1e-15);
  EXPECT_NEAR(c[0][1][1].item<double>(), 0.2, 1e-15);
  EXPECT_NEAR(c[0][1][0].item<double>(), std::sqrt(1.0 + 0.04), 1e-15);
}

TEST(ContactMap, TreeAndPairwiseImplementationsAgree) {
  at::manual_seed(3);
  const at::Tensor obj = at::rand({6, 1024, 3}, at::kFloat) * 0.3;
  const at::Tensor hands = at::rand({2, 6, 778, 3}, at::kFloat) * 0.3 + 0.05;
  const at::Tensor a = contact_maps(obj, hands);
  const at::Tensor b = contact_maps_exhaustive(obj, hands);
  ASSERT_EQ(a.sizes(), (at::IntArrayRef{6, 2, 1024}));
  EXPECT_LT((a - b).abs().max().item<float>(), 2e-7);
}

TEST(ContactMap, GradientPointsFromTheNearestHandPointToTheObjectPoint) {
  at::Tensor obj = at::zeros({1, 1, 3}, at::kDouble);
  at::Tensor hands = at::zeros({2, 1, 2, 3}, at::kDouble);
  hands[0][0][0] = at::tensor({0.0, 0.0, 0.1}, at::kDouble);
  hands[0][0][1] = at::tensor({0.0, 0.3, 0.0}, at::kDouble);
  hands[1][0][0] = at::tensor({0.2, 0.0, 0.0}, at::kDouble);
  hands[1][0][1] = at::tensor({0.0, 0.3, 0.0}, at::kDouble);
  hands.requires_grad_(true);
  contact_maps(obj, hands).sum().backward();
  const at::Tensor g = hands.grad();
  // d||p - o|| / dp = (p - o) / ||p - o||, for the nearest point only.
  EXPECT_NEAR(g[0][0][0][2].item<double>(), 1.0, 1e-12);
  EXPECT_NEAR(g[1][0][0][0].item<double>(), 1.0, 1e-12);
  EXPECT_EQ(g[0][0][1].abs().sum().item<double>(), 0.0);
}

TEST(ContactMap, HitPointsAreTheEncodersHitVertices) {
  const ArticulatedObject o = make_object("laptop", 2);
  at::Tensor s = at::zeros({2, 7});
  s[0][0] = 0.4;
  s[1][0] = 1.3;
  s[1][4] = 0.5;  // root pose does not enter the canonical frame
  const BpsBasis basis = load_bps_basis(find_data_file(default_basis_file(BpsVariant::PerPart)));
  const ObjectEncoding e = encode_object(o, s, basis, BpsVariant::PerPart);
  const at::Tensor p = basis_hit_points(o, s, e.hit_indices);
  ASSERT_EQ(p.sizes(), (at::IntArrayRef{2, 1024, 3}));
  // Scaled by s_o, a hit point is basis point + feature.
  const at::Tensor expected = object_points_from_bps(e.features, e.basis_points, at::scalar_tensor(e.scale));
  EXPECT_LT((p - expected).abs().max().item<float>(), 1e-5);
}

// Every variant's features give back its hit vertices in metres: divided by s_o for the
// normalised encoders, as they are for U-BPS (`bimart model check --guidance` divided U-BPS
// points by s_o too, placing them 2-4x too close to the origin).
TEST(ContactMap, EveryVariantsFeaturesGiveItsHitVertices) {
  const ArticulatedObject o = make_object("box", 1);
  at::Tensor s = at::zeros({2, 7});
  s[0][0] = 0.2;
  s[1][0] = 1.1;
  for (BpsVariant v : {BpsVariant::Uniform, BpsVariant::PartAgnostic, BpsVariant::PerPart}) {
    SCOPED_TRACE(static_cast<int>(v));
    const BpsBasis basis = load_bps_basis(find_data_file(default_basis_file(v)));
    const ObjectEncoding e = encode_object(o, s, basis, v);
    const at::Tensor hits = basis_hit_points(o, s, e.hit_indices);
    const at::Tensor s_o = e.global_states.select(1, 6);
    EXPECT_LT((object_points_from_bps(e.features, e.basis_points, s_o, v) - hits).abs().max().item<float>(), 1e-5);
  }
}

// With both hands at the world position of hit vertex 0 (posed here with Eigen), every entry
// is that vertex's distance to the row's vertex in the canonical frame: the root pose is
// applied to the object points, and distances are rigid-invariant.
TEST(ContactMap, WorldContactMapsPoseTheHitVerticesByTheRootPose) {
  const ArticulatedObject o = make_object("laptop", 2);
  at::Tensor s = at::zeros({2, 7}, at::kDouble);
  s[0] = at::tensor({0.4, 0.3, -0.2, 0.9, 0.1, -0.5, 0.7}, at::kDouble);
  s[1] = at::tensor({1.3, -1.1, 0.4, 0.2, -0.3, 0.2, 1.1}, at::kDouble);
  const BpsBasis basis = load_bps_basis(find_data_file(default_basis_file(BpsVariant::PerPart)));
  const ObjectEncoding e = encode_object(o, s.to(at::kFloat), basis, BpsVariant::PerPart);
  const at::Tensor canonical = basis_hit_points(o, s, e.hit_indices).to(at::kDouble);  // [2, 1024, 3]
  at::Tensor hands = at::zeros({2, 2, 1, 3}, at::kDouble);
  for (int t = 0; t < 2; ++t) {
    const Eigen::Isometry3d pose = canonical_to_world(ObjectState::from_row(s[t].contiguous().data_ptr<double>()));
    const at::Tensor p0 = canonical[t][0];
    const Eigen::Vector3d w = pose * Eigen::Vector3d(p0[0].item<double>(), p0[1].item<double>(), p0[2].item<double>());
    for (int h = 0; h < 2; ++h) hands[h][t][0] = at::tensor({w.x(), w.y(), w.z()}, at::kDouble);
  }
  const at::Tensor c = world_contact_maps(o, s, e.hit_indices, hands);
  ASSERT_EQ(c.sizes(), (at::IntArrayRef{2, 2, 1024}));
  const at::Tensor expected = (canonical - canonical.narrow(1, 0, 1)).norm(2, {2});  // [2, 1024]
  for (int h = 0; h < 2; ++h) EXPECT_LT((c.select(1, h) - expected).abs().max().item<double>(), 1e-9);
  EXPECT_GT(expected.max().item<double>(), 0.1);  // the object spans decimetres: the test can tell
}

TEST(ContactMap, BadShapesAreClearErrors) {
  EXPECT_THROW(contact_maps(at::zeros({2, 5, 3}), at::zeros({2, 3, 4, 3})), Error);
  EXPECT_THROW(contact_maps(at::zeros({2, 5}), at::zeros({2, 2, 4, 3})), Error);
  const ArticulatedObject o = make_object("box", 0);
  at::Tensor idx = at::full({1, 1024}, o.top.num_vertices() + o.bottom.num_vertices(), at::kLong);
  EXPECT_THROW(basis_hit_points(o, at::zeros({1, 7}), idx), Error);
}

}  // namespace
}  // namespace bimart
