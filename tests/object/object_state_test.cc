#include "core/object/object_state.h"

#include <gtest/gtest.h>

#include <ATen/ATen.h>
#include <cmath>
#include <limits>

#include "core/geometry/rotation.h"
#include "core/object/object_batch.h"
#include "core/util/error.h"

namespace bimart {
namespace {

// Closed laptop-like object: bottom below y = 0, top above, both towards -x of the hinge.
ArticulatedObject two_boxes() {
  ArticulatedObject o;
  o.name = "two_boxes";
  o.top = make_box({-0.3, 0.0, -0.2}, {0.0, 0.1, 0.2});
  o.bottom = make_box({-0.3, -0.2, -0.2}, {0.0, 0.0, 0.2});
  return o;
}

TEST(ObjectState, FromRowAndBack) {
  const double row[7] = {0.5, 0.1, 0.2, 0.3, 1, 2, 3};
  const ObjectState s = ObjectState::from_row(row);
  EXPECT_EQ(s.angle, 0.5);
  EXPECT_EQ(s.root_rotation, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(s.root_translation, Eigen::Vector3d(1, 2, 3));
  for (int i = 0; i < 7; ++i) EXPECT_EQ(s.to_row()[i], row[i]);
}

TEST(ObjectState, NonFiniteIsAnErrorNamingTheField) {
  float row[7] = {0, 0, 0, 0, 0, 0, 0};
  row[5] = std::numeric_limits<float>::quiet_NaN();
  try {
    ObjectState::from_row(row);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ty"), std::string::npos) << e.what();
  }
}

TEST(ObjectPose, TopTurnsAboutMinusZAndBottomStays) {
  const ArticulatedObject o = two_boxes();
  for (double a : {0.0, 0.4, M_PI / 2, 2.0}) {
    const PosedObject p = pose_canonical(o, a);
    // Vertex 1 of the top box is (0, 0, -0.2)... take vertex 0: (-0.3, 0, -0.2).
    const Eigen::Vector3d v = o.top.vertices.row(0);
    ASSERT_EQ(v, Eigen::Vector3d(-0.3, 0, -0.2));
    // About -z by a: (x, y) -> (x cos a + y sin a, -x sin a + y cos a); -x lifts to +y.
    const Eigen::Vector3d expected(-0.3 * std::cos(a), 0.3 * std::sin(a), -0.2);
    EXPECT_LT((Eigen::Vector3d(p.top.row(0)) - expected).norm(), 1e-15) << a;
    EXPECT_EQ(p.bottom, o.bottom.vertices);
  }
}

TEST(ObjectPose, RootPoseIsAppliedAfterTheHinge) {
  const ArticulatedObject o = two_boxes();
  ObjectState s;
  s.angle = M_PI / 2;
  s.root_rotation = Eigen::Vector3d(M_PI / 2, 0, 0);  // quarter turn about +x: y -> z
  s.root_translation = Eigen::Vector3d(1, 2, 3);
  const PosedObject p = pose_world(o, s);
  // Top vertex (-0.3, 0, -0.2): hinge -> (0, 0.3, -0.2); root rotation -> (0, 0.2, 0.3); + t.
  EXPECT_LT((Eigen::Vector3d(p.top.row(0)) - Eigen::Vector3d(1, 2.2, 3.3)).norm(), 1e-14);
  // Bottom vertex 0 (-0.3, -0.2, -0.2): no hinge -> (-0.3, 0.2, -0.2) + t.
  EXPECT_LT((Eigen::Vector3d(p.bottom.row(0)) - Eigen::Vector3d(0.7, 2.2, 2.8)).norm(), 1e-14);
  // The same through the transforms.
  const Eigen::Isometry3d T = canonical_to_world(s) * top_to_canonical(s.angle);
  EXPECT_LT((T * Eigen::Vector3d(-0.3, 0, -0.2) - Eigen::Vector3d(1, 2.2, 3.3)).norm(), 1e-14);
}

TEST(ObjectPose, BatchEqualsPerFrame) {
  const ArticulatedObject o = two_boxes();
  const at::Tensor states = at::tensor({0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,          // rest
                                        0.7, 1e-10, -2e-10, 0.0, 0.1, 0.2, 0.3,  // tiny rotation
                                        1.9, 0.3, -1.2, 2.0, -1.0, 0.5, 2.0,     // general
                                        -0.4, 0.0, 3.1, 0.1, 0.0, 0.0, 0.0},     // near pi
                                       at::kDouble)
                               .view({4, 7});
  const PosedObjectBatch b = pose_object_batch(o, states);
  ASSERT_EQ(b.top.sizes(), (at::IntArrayRef{4, 8, 3}));
  ASSERT_EQ(b.bottom.sizes(), (at::IntArrayRef{4, 8, 3}));
  const PosedObjectBatch bf = pose_object_batch(o, states.to(at::kFloat));
  EXPECT_EQ(bf.top.scalar_type(), at::kFloat);
  for (int t = 0; t < 4; ++t) {
    const PosedObject p = pose_world(o, ObjectState::from_row(states[t].contiguous().data_ptr<double>()));
    for (int i = 0; i < 8; ++i)
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(b.top[t][i][c].item<double>(), p.top(i, c), 1e-14);
        EXPECT_NEAR(b.bottom[t][i][c].item<double>(), p.bottom(i, c), 1e-14);
        EXPECT_NEAR(bf.top[t][i][c].item<double>(), p.top(i, c), 1e-5);
      }
  }
}

TEST(ObjectPose, BatchRejectsBadInput) {
  const ArticulatedObject o = two_boxes();
  EXPECT_THROW(pose_object_batch(o, at::zeros({3, 6})), Error);
  at::Tensor s = at::zeros({2, 7});
  s[1][3] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(pose_object_batch(o, s), Error);
}

TEST(ObjectScale, AnalyticForBoxesAndIndependentOfTheAngle) {
  ArticulatedObject o = two_boxes();
  // Farthest corners: (-0.3, +-0.2, +-0.2) in the bottom box.
  EXPECT_NEAR(object_scale(o), 0.85 / std::sqrt(0.09 + 0.04 + 0.04), 1e-15);
  ArticulatedObject open = o;
  open.top = posed_top(o, 1.3);
  EXPECT_NEAR(object_scale(open), object_scale(o), 1e-14);
}

}  // namespace
}  // namespace bimart
