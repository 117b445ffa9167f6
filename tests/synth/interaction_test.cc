#include "core/synth/interaction.h"

#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include "core/geometry/mesh_distance.h"
#include "core/geometry/rotation.h"
#include "core/hand/lbs.h"
#include "core/metrics/hand_vertices.h"
#include "core/metrics/multimodality.h"
#include "core/metrics/sequence_metrics.h"
#include "core/object/families/families.h"
#include "shipped_hands.h"
#include "core/util/error.h"

namespace bimart {
namespace {

const std::array<const HandModel*, 2>& hands() { return test::shipped_hands(); }

struct Case {
  ArticulatedObject object;
  std::unique_ptr<ObjectDistance> distance;
  Trajectory trajectory;
};

Case make_case(const std::string& category, SequenceKind kind, std::uint64_t seed) {
  Case c;
  c.object = make_object(category, seed);
  c.distance = std::make_unique<ObjectDistance>(c.object);
  c.trajectory = plan_trajectory(c.object, kind, seed);
  return c;
}

// As the data set writer does: a new trajectory when no motion is found for one.
HandMotion synthesize(Case& c, SequenceKind kind, std::uint64_t seed, InteractionInfo* info = nullptr) {
  for (std::uint64_t t = 0;; ++t) {
    try {
      return synthesize_hands(c.object, *c.distance, hands(), c.trajectory, seed, {}, info);
    } catch (const Error&) {
      if (t == 4) throw;
      c.trajectory = plan_trajectory(c.object, kind, 1000 + t);
    }
  }
}

SequenceMetrics metrics_of(const Case& c, const HandMotion& m) {
  SequenceData d;
  d.object_states = c.trajectory.tensor();
  d.hand_vertices = hand_vertices(m);
  return evaluate_sequence(c.object, *c.distance, d);
}

// World transform of the top part at a frame, and of a hand from its MANO parameters.
Eigen::Isometry3d hand_transform(const HandModel& model, const HandParams& p, int f) {
  Eigen::Vector3d rot, trans;
  for (int k = 0; k < 3; ++k) rot[k] = p.rot[f][k].item<double>(), trans[k] = p.trans[f][k].item<double>();
  Eigen::VectorXd betas(10);
  for (int k = 0; k < 10; ++k) betas[k] = p.shape[k].item<double>();
  const Eigen::Vector3d j0 = lbs<double>(model, Eigen::Vector3d::Zero(), Eigen::VectorXd::Zero(45),
                                         Eigen::Vector3d::Zero(), betas).joints.row(0).transpose();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = axis_angle_to_matrix(rot);
  T.translation() = trans + j0 - T.linear() * j0;
  return T;
}

TEST(Interaction, UseSequenceScoresLikeCaptureData) {
  Case c = make_case("box", SequenceKind::Use, 4);
  InteractionInfo info;
  const HandMotion m = synthesize(c, SequenceKind::Use, 1, &info);
  const SequenceMetrics s = metrics_of(c, m);
  EXPECT_EQ(s.pen_1cm.hits, 0);
  EXPECT_EQ(s.pen_5mm.hits, 0);
  ASSERT_GT(s.contact.frames, 0);
  EXPECT_EQ(s.contact.hits, s.contact.frames);
  ASSERT_GT(s.articulation.frames, 0);
  EXPECT_EQ(s.articulation.hits, s.articulation.frames);
  EXPECT_LE(info.depth, InteractionOptions{}.max_depth_moving);
  EXPECT_GE(info.clearance, InteractionOptions{}.hand_clearance);
  ASSERT_GE(info.driver, 0);
  EXPECT_EQ(info.part[info.driver], ObjectPart::Top);
  EXPECT_EQ(info.part[1 - info.driver], ObjectPart::Bottom);
  // The driving hand follows the hinge: rigid relative to the top part while holding.
  const HandModel& model = *hands()[info.driver];
  const auto rel = [&](int f) {
    return world_from_part(c.trajectory.states[f], ObjectPart::Top).inverse() *
           hand_transform(model, m.hands[info.driver], f);
  };
  const Eigen::Isometry3d r0 = rel(c.trajectory.first_move);
  for (int f = c.trajectory.first_move; f <= c.trajectory.last_move; f += 7) {
    EXPECT_LT((rel(f).translation() - r0.translation()).norm(), 1e-5) << f;
    EXPECT_LT((rel(f).linear() - r0.linear()).norm(), 1e-5) << f;
  }
}

TEST(Interaction, GrabSequenceHoldsTheBottomWithBothHands) {
  Case c = make_case("box", SequenceKind::Grab, 2);
  InteractionInfo info;
  const HandMotion m = synthesize(c, SequenceKind::Grab, 7, &info);
  const SequenceMetrics s = metrics_of(c, m);
  EXPECT_EQ(s.pen_1cm.hits, 0);
  EXPECT_EQ(s.contact.hits, s.contact.frames);
  EXPECT_EQ(info.part[0], ObjectPart::Bottom);
  EXPECT_EQ(info.part[1], ObjectPart::Bottom);
  EXPECT_EQ(info.driver, -1);
  // Both hands touch the object (within 5 mm) in every frame where it moves.
  const at::Tensor v = hand_vertices(m);
  for (int f = c.trajectory.first_move; f <= c.trajectory.last_move; f += 5)
    for (int h = 0; h < 2; ++h) {
      const at::Tensor vf = v[h][f].to(at::kDouble).contiguous();
      Points3 p = Eigen::Map<const Points3>(vf.data_ptr<double>(), vf.size(0), 3);
      EXPECT_GT(c.distance->max_signed_distance(c.trajectory.states[f], p), -0.005) << "hand " << h << " frame " << f;
    }
}

TEST(Interaction, HandsNeverInterpenetrate) {
  for (const char* category : {"phone", "ketchup", "notebook", "mixer"}) {
    for (SequenceKind kind : {SequenceKind::Grab, SequenceKind::Use}) {
      SCOPED_TRACE(std::string(category) + " " + kind_name(kind));
      Case c = make_case(category, kind, 5);
      const HandMotion m = synthesize(c, kind, 3);
      const at::Tensor v = hand_vertices(m).to(at::kDouble).contiguous();
      for (int f = 0; f < c.trajectory.num_frames(); f += 6) {
        const at::Tensor a = v[0][f].contiguous(), b = v[1][f].contiguous();
        const TriangleMesh left{Eigen::Map<const Points3>(a.data_ptr<double>(), a.size(0), 3), hands()[0]->faces};
        const Points3 right = Eigen::Map<const Points3>(b.data_ptr<double>(), b.size(0), 3);
        EXPECT_LT(MeshDistance(left).max_signed_distance(right), 0.005) << f;
      }
      EXPECT_EQ(metrics_of(c, m).pen_1cm.hits, 0);
    }
  }
}

TEST(Interaction, SameSeedSameMotion) {
  Case c = make_case("microwave", SequenceKind::Use, 1);
  const HandMotion a = synthesize(c, SequenceKind::Use, 9);  // settles on a trajectory
  const HandMotion b = synthesize_hands(c.object, *c.distance, hands(), c.trajectory, 9);
  const HandMotion d = synthesize_hands(c.object, *c.distance, hands(), c.trajectory, 10);
  for (int h = 0; h < 2; ++h) {
    EXPECT_TRUE(at::equal(a.hands[h].rot, b.hands[h].rot));
    EXPECT_TRUE(at::equal(a.hands[h].pose, b.hands[h].pose));
    EXPECT_TRUE(at::equal(a.hands[h].trans, b.hands[h].trans));
    EXPECT_TRUE(at::equal(a.hands[h].shape, b.hands[h].shape));
  }
  EXPECT_FALSE(at::equal(a.hands[0].trans, d.hands[0].trans));
}

TEST(Interaction, RefusesAMotionlessTrajectoryAndSwappedModels) {
  const Case c = make_case("box", SequenceKind::Grab, 1);
  Trajectory still = c.trajectory;
  still.first_move = 2;
  EXPECT_THROW(synthesize_hands(c.object, *c.distance, hands(), still, 1), Error);
  const std::array<const HandModel*, 2> swapped{hands()[1], hands()[0]};
  EXPECT_THROW(synthesize_hands(c.object, *c.distance, swapped, c.trajectory, 1), Error);
}

}  // namespace
}  // namespace bimart
