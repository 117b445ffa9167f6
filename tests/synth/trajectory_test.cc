#include "core/synth/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>

#include <ATen/ATen.h>

#include "core/object/families/families.h"
#include "core/object/object_state.h"
#include "core/synth/motion_table.h"

namespace bimart {
namespace {

double lowest_point(const ArticulatedObject& o, const ObjectState& s) {
  const PosedObject p = pose_world(o, s);
  return std::min(p.top.col(1).minCoeff(), p.bottom.col(1).minCoeff());
}

bool same(const ObjectState& a, const ObjectState& b) { return a.to_row() == b.to_row(); }

TEST(Trajectory, MinimumJerkProfile) {
  EXPECT_DOUBLE_EQ(min_jerk(0), 0);
  EXPECT_DOUBLE_EQ(min_jerk(1), 1);
  EXPECT_DOUBLE_EQ(min_jerk(0.5), 0.5);
  EXPECT_DOUBLE_EQ(min_jerk(-1), 0);
  EXPECT_NEAR(min_jerk(0.25) + min_jerk(0.75), 1.0, 1e-15);  // symmetric
  // Zero velocity at both ends: the first difference is third order in the step.
  EXPECT_LT(min_jerk(1e-3), 1e-8);
}

TEST(Trajectory, EveryCategoryHasATableRow) {
  for (const auto& c : object_categories()) {
    bool found = false;
    for (const auto& row : category_motions()) found |= row.category == c;
    EXPECT_TRUE(found) << c;
  }
}

TEST(Trajectory, StillThenMovingThenStillWithinTheFrameBudget) {
  for (const auto& category : object_categories()) {
    const ArticulatedObject o = make_object(category, 3);
    for (SequenceKind kind : {SequenceKind::Grab, SequenceKind::Use}) {
      SCOPED_TRACE(category + " " + kind_name(kind));
      const Trajectory t = plan_trajectory(o, kind, 11);
      ASSERT_GE(t.num_frames(), 120);
      ASSERT_LE(t.num_frames(), 300);
      ASSERT_GE(t.first_move, 20);
      ASSERT_LT(t.last_move + 12, t.num_frames());
      for (int f = 0; f < t.first_move; ++f) ASSERT_TRUE(same(t.states[f], t.states[0])) << f;
      for (int f = t.last_move + 1; f < t.num_frames(); ++f) ASSERT_TRUE(same(t.states[f], t.states.back())) << f;
      EXPECT_FALSE(same(t.states[t.first_move], t.states[t.first_move + 1]));
      EXPECT_FALSE(same(t.states[t.last_move], t.states[t.last_move + 1]));
      // Rests on the table (y = 0), or on its stand, at the start and at the end.
      const double support = category_motion(category).support;
      EXPECT_NEAR(lowest_point(o, t.states.front()), support, 1e-9);
      EXPECT_NEAR(lowest_point(o, t.states.back()), support, 1e-6);
      double lo = 1e9, hi = -1e9;
      for (const auto& s : t.states) lo = std::min(lo, s.angle), hi = std::max(hi, s.angle);
      EXPECT_GE(lo, o.angle_min - 1e-12);
      EXPECT_LE(hi, o.angle_max + 1e-12);
      if (kind == SequenceKind::Grab) EXPECT_EQ(lo, hi);      // hinge fixed
      else EXPECT_GT(hi - lo, 0.2 * (o.angle_max - o.angle_min));  // the hinge really moves
      // Smooth: no frame-to-frame jump above 3 cm or 0.1 rad.
      for (int f = 1; f < t.num_frames(); ++f) {
        EXPECT_LT((t.states[f].root_translation - t.states[f - 1].root_translation).norm(), 0.03);
        EXPECT_LT(std::abs(t.states[f].angle - t.states[f - 1].angle), 0.1);
      }
    }
  }
}

TEST(Trajectory, GrabsLiftTheObject) {
  const ArticulatedObject o = make_object("box", 1);
  const Trajectory t = plan_trajectory(o, SequenceKind::Grab, 5);
  double top = 0;
  for (const auto& s : t.states) top = std::max(top, lowest_point(o, s));
  const auto& m = category_motion("box");
  EXPECT_GE(top, 0.5 * m.lift.min);  // the tilt may lower one corner a little
}

TEST(Trajectory, SameSeedSameTrajectoryOtherSeedAnother) {
  const ArticulatedObject o = make_object("laptop", 2);
  const Trajectory a = plan_trajectory(o, SequenceKind::Use, 9), b = plan_trajectory(o, SequenceKind::Use, 9),
                   c = plan_trajectory(o, SequenceKind::Use, 10);
  EXPECT_TRUE(at::equal(a.tensor(), b.tensor()));
  EXPECT_FALSE(a.tensor().sizes() == c.tensor().sizes() && at::equal(a.tensor(), c.tensor()));
}

TEST(Trajectory, TensorHasTheStateLayout) {
  const ArticulatedObject o = make_object("phone", 1);
  const Trajectory t = plan_trajectory(o, SequenceKind::Use, 1);
  const at::Tensor x = t.tensor();
  ASSERT_EQ(x.sizes(), (std::vector<int64_t>{t.num_frames(), 7}));
  const int f = t.num_frames() / 2;
  EXPECT_FLOAT_EQ(x[f][0].item<float>(), static_cast<float>(t.states[f].angle));
  EXPECT_FLOAT_EQ(x[f][5].item<float>(), static_cast<float>(t.states[f].root_translation.y()));
}

}  // namespace
}  // namespace bimart
