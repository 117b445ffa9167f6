#include "core/synth/grasp.h"

#include <gtest/gtest.h>

#include "core/hand/lbs.h"
#include "core/object/families/primitives.h"
#include "shipped_hands.h"

namespace bimart {
namespace {

const HandModel& shipped(HandSide side) { return *test::shipped_hands()[side == HandSide::Left ? 0 : 1]; }

// A 30 x 10 x 20 cm box below y = 0 (the bottom part) and a thin lid above it.
ArticulatedObject box_object() {
  ArticulatedObject o;
  o.name = "test_box";
  o.bottom = shapes::rounded_box({-0.30, -0.10, -0.10}, {0, 0, 0.10}, 0.005, 0.01);
  o.top = shapes::rounded_box({-0.30, 0, -0.10}, {0, 0.01, 0.10}, 0.003, 0.01);
  o.angle_max = 1.5;
  return o;
}

TEST(HandGeometry, AxesOfTheShippedHands) {
  for (HandSide side : {HandSide::Left, HandSide::Right}) {
    const HandGeometry g = hand_geometry(shipped(side), Eigen::VectorXd::Zero(10));
    EXPECT_NEAR(g.finger_dir.x(), side == HandSide::Right ? -1 : 1, 0.1);  // fingers along -x (right)
    EXPECT_NEAR(g.palm_normal.dot(g.finger_dir), 0, 1e-12);
    size_t total = g.palm.size();
    for (const auto& d : g.digits) {
      EXPECT_GT(d.size(), 20u);
      total += d.size();
    }
    EXPECT_EQ(total, static_cast<size_t>(shipped(side).num_vertices()));
    // The palm point lies on the palm side of the wrist, between wrist and knuckles.
    EXPECT_LT(g.palm_point.y(), g.wrist.y());
    EXPECT_GT((g.palm_point - g.wrist).dot(g.finger_dir), 0.02);
  }
}

TEST(GraspPlanner, PalmOnTheSurfaceNothingDeepSomethingTouching) {
  const ArticulatedObject o = box_object();
  const ObjectDistance dist(o);
  const GraspPlanner planner(o, dist);
  for (HandSide side : {HandSide::Left, HandSide::Right}) {
    const HandGeometry hand = hand_geometry(shipped(side), Eigen::VectorXd::Zero(10));
    for (ObjectPart part : {ObjectPart::Bottom, ObjectPart::Top}) {
      Rng rng(3);
      GraspRequest req;
      req.part = part;
      req.angle = 0.8;
      const auto g = planner.plan(hand, req, rng);
      ASSERT_TRUE(g.has_value());
      EXPECT_LE(g->depth, 0.002);
      EXPECT_GE(g->contacts, 10);
      // The palm faces into the surface at the site.
      const Eigen::Vector3d palm = g->part_from_hand.linear() * hand.palm_normal;
      EXPECT_LT(palm.dot(g->normal), -0.99);
      const Eigen::Vector3d palm_point = g->part_from_hand * hand.palm_point;
      EXPECT_LT((palm_point - g->site).norm(), 0.03);
      // Its own numbers agree with an independent check of the posed vertices.
      const Points3 v = local_hand_vertices(hand, g->finger_pose);
      Points3 w(v.rows(), 3);
      for (Eigen::Index i = 0; i < v.rows(); ++i) w.row(i) = (g->part_from_hand * v.row(i).transpose()).transpose();
      EXPECT_NEAR(planner.depth(part, req.angle, w), g->depth, 1e-9);
      for (double c : g->curl) {
        EXPECT_GE(c, 0);
        EXPECT_LE(c, 1);
      }
    }
  }
}

TEST(GraspPlanner, SiteFilterIsObeyed) {
  const ArticulatedObject o = box_object();
  const ObjectDistance dist(o);
  const GraspPlanner planner(o, dist);
  const HandGeometry hand = hand_geometry(shipped(HandSide::Right), Eigen::VectorXd::Zero(10));
  Rng rng(5);
  GraspRequest req;
  req.part = ObjectPart::Bottom;
  req.accept_site = [](const Eigen::Vector3d&, const Eigen::Vector3d& n) { return n.z() > 0.9; };  // the +z face
  const auto g = planner.plan(hand, req, rng);
  ASSERT_TRUE(g.has_value());
  EXPECT_GT(g->normal.z(), 0.9);
  // Nothing passes: no grasp, not a crash.
  req.accept_site = [](const Eigen::Vector3d&, const Eigen::Vector3d&) { return false; };
  EXPECT_FALSE(planner.plan(hand, req, rng).has_value());
}

}  // namespace
}  // namespace bimart
