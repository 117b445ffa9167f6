// Exit planes (core/refine/exit_plane.h) on a thin slab with known faces: a ray leaves
// where the geometry says, and a ray along the slab's plane, inside it past kExitReach,
// gives no plane (it once gave one where it gave up, and hands were pushed 6 cm off).
#include "core/refine/exit_plane.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/object/families/primitives.h"
#include "tests/refine/test_objects.h"

namespace bimart {
namespace {

// A slab 1 cm thick, top face z = 0.
ArticulatedObject thin_slab() { return test::slab(0.01, 0.002); }

TEST(ExitPlane, ARayLeavesThroughTheFaceItMeets) {
  const ObjectDistance dist(thin_slab());
  const Eigen::Vector3d p(0.0, 0.0, -0.004);  // 4 mm under the top, 6 mm over the underside
  // Tilted 45° up: meets the top face 4 mm up, 4 mm along.
  const auto up = exit_plane(dist, ObjectState{}, p, Eigen::Vector3d(1, 0, 1).normalized());
  ASSERT_TRUE(up.has_value());
  EXPECT_NEAR(up->point.z(), 0.0, 5e-4);
  EXPECT_NEAR(up->point.x(), 0.004, 1e-3);
  EXPECT_GT(up->normal.z(), 0.99);
  // Straight down: the underside, its normal facing down, the way the ray goes.
  const auto down = exit_plane(dist, ObjectState{}, p, -Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(down.has_value());
  EXPECT_NEAR(down->point.z(), -0.01, 5e-4);
  EXPECT_LT(down->normal.z(), -0.99);
}

TEST(ExitPlane, ARayAlongAThinPartGivesNoPlane) {
  const ObjectDistance dist(thin_slab());
  const Eigen::Vector3d p(0.0, 0.0, -0.005);
  // Along the slab: inside for 20 cm, past the reach.
  EXPECT_FALSE(exit_plane(dist, ObjectState{}, p, Eigen::Vector3d::UnitX()).has_value());
  // 2° up: it would reach the top face only after 14 cm.
  const double a = 2.0 * M_PI / 180.0;
  EXPECT_FALSE(exit_plane(dist, ObjectState{}, p, Eigen::Vector3d(std::cos(a), 0, std::sin(a))).has_value());
  // Near the slab's edge the same ray leaves through the edge face, within reach.
  const auto edge = exit_plane(dist, ObjectState{}, Eigen::Vector3d(0.17, 0.0, -0.005), Eigen::Vector3d::UnitX());
  ASSERT_TRUE(edge.has_value());
  EXPECT_NEAR(edge->point.x(), 0.2, 1e-3);
  EXPECT_GT(edge->normal.x(), 0.99);
}

TEST(ExitPlane, TheWayOutPointsFromTheInsideVerticesToTheRest) {
  Points3 v(4, 3);
  v << 0, 0, -0.005,  //
      0.01, 0, -0.005,  //
      0, 0, 0.02,       //
      0.01, 0, 0.04;
  const Eigen::Vector3d e = exit_direction(v, {0, 1});
  EXPECT_NEAR(e.x(), 0.0, 1e-12);
  EXPECT_NEAR(e.z(), 1.0, 1e-12);  // from (0.005, 0, -0.005) to (0.005, 0, 0.03)
  EXPECT_TRUE(exit_direction(v, {}).isZero());            // nothing trapped
  EXPECT_TRUE(exit_direction(v, {0, 1, 2, 3}).isZero());  // wholly trapped
}

// A closed box of 5 mm walls, 20 × 20 × 10 cm, its lid the top part (its top face z = 0).
ArticulatedObject hollow_box() { return test::hollow_box(0.1); }

TEST(ExitPlane, FromACavityThroughTheWallBetween) {
  const ObjectDistance dist(hollow_box());
  const Eigen::Vector3d p(0.0, -0.07, -0.05);  // in the box, 2.5 cm from the front wall's inside (y = -0.095)
  ASSERT_LT(dist.query(ObjectState{}, p).signed_distance, -0.02);
  // Towards the front: the plane is the wall's outside face, y = -0.1, facing out.
  const auto front = exit_plane_through(dist, ObjectState{}, p, -Eigen::Vector3d::UnitY());
  ASSERT_TRUE(front.has_value());
  EXPECT_NEAR(front->point.y(), -0.1, 5e-4);
  EXPECT_LT(front->normal.y(), -0.99);
  // Up: through the lid, its top face z = 0.
  const auto up = exit_plane_through(dist, ObjectState{}, p, Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(up.has_value());
  EXPECT_NEAR(up->point.z(), 0.0, 5e-4);
  // Far out of the box, pointing away from it: nothing to pass through.
  EXPECT_FALSE(exit_plane_through(dist, ObjectState{}, Eigen::Vector3d(0, -0.2, -0.05), -Eigen::Vector3d::UnitY()));
  // The lid open (the top part far away): up through the opening, no wall.
  ArticulatedObject open = hollow_box();
  open.top = shapes::rounded_box({1.0, 1.0, 1.0}, {1.05, 1.05, 1.05}, 0.005, 0.01);
  const ObjectDistance open_dist(open);
  EXPECT_FALSE(exit_plane_through(open_dist, ObjectState{}, p, Eigen::Vector3d::UnitZ()).has_value());
  // The cavity as the distance reads it: the point is in it, 2.5 cm deep, the wall is not.
  const auto cavity = dist.cavity_points(ObjectState{}, (Points3(2, 3) << p.transpose(), 0, -0.0975, -0.05).finished(), 0.005);
  ASSERT_EQ(cavity.size(), 1u);
  EXPECT_EQ(cavity[0], 0);
}

}  // namespace
}  // namespace bimart
