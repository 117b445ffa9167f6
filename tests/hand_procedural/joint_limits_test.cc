// Anatomical joint limits (core/hand/joint_limits.h) on the procedural hands: the angles of
// known poses, the ranges flagging what they should, and Jet derivatives against numeric
// ones.
#include "core/hand/joint_limits.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Geometry>

#include "core/geometry/rotation.h"
#include "tests/hand_procedural/fixture.h"

namespace bimart {
namespace {

const HandModel& hand(int side) { return side == 0 ? test::left_hand() : test::right_hand(); }
constexpr double kDeg = 180.0 / M_PI;

// Joint j's bone direction as the limits see it: a small turn about e twists it by
// about 0.1 rad · (e·bone).
Eigen::Vector3d bone_of(const JointLimits& L, int j) {
  Eigen::Vector3d bone;
  for (int c = 0; c < 3; ++c) bone[c] = L.angles(j, 0.1 * Eigen::Vector3d::Unit(c))[2];
  return bone.normalized();
}

TEST(JointLimits, RestPoseHasNoBendAndNothingOutside) {
  for (int side : {0, 1}) {
    const JointLimits L(hand(side));
    for (int j = 0; j < 15; ++j) EXPECT_LT(L.angles(j, Eigen::Vector3d::Zero()).norm(), 1e-6) << j;
    EXPECT_EQ(L.largest_excess(Eigen::VectorXd::Zero(45)), 0.0);
  }
}

// procedural_digit_pose bends each finger joint about its flexion axis by curl times
// 1.45 (MCP), 1.70 (PIP), 1.10 (DIP) rad, the same on both sides (the left one mirrored).
TEST(JointLimits, CurledFingersFlexTowardsThePalmByTheirAngles) {
  for (int side : {0, 1}) {
    const JointLimits L(hand(side));
    const Eigen::VectorXd pose = procedural_digit_pose(static_cast<HandSide>(side), {0.5, 0.5, 0.5, 0.5, 0.5},
                                                       {0, 0, 0, 0, 0});
    for (int finger = 0; finger < 4; ++finger)
      for (int k = 0; k < 3; ++k) {
        const int j = 3 * finger + k;
        const Eigen::Vector3d a = L.angles(j, pose.segment<3>(3 * j));
        constexpr double kCurl1[3] = {1.45, 1.70, 1.10};
        EXPECT_NEAR(a[0], 0.5 * kCurl1[k] * kDeg, 1.5) << "side " << side << " joint " << j;
        EXPECT_NEAR(a[1], 0, 1.5) << "side " << side << " joint " << j;
        EXPECT_NEAR(a[2], 0, 1e-6) << "side " << side << " joint " << j;
      }
    EXPECT_EQ(L.largest_excess(pose), 0.0);
  }
}

TEST(JointLimits, FlagsAFingerBentBackwardsSidewaysOrTwisted) {
  for (int side : {0, 1}) {
    const JointLimits L(hand(side));
    const Eigen::VectorXd curled = procedural_digit_pose(static_cast<HandSide>(side), {0.3, 0.3, 0.3, 0.3, 0.3},
                                                         {0, 0, 0, 0, 0});
    // Index PIP (joint 1): its flexion axis is the curled pose's direction; −60° of it.
    const Eigen::Vector3d axis = curled.segment<3>(3).normalized();
    Eigen::VectorXd pose = curled;
    pose.segment<3>(3) = -60.0 / kDeg * axis;
    std::string where;
    EXPECT_NEAR(L.largest_excess(pose, &where), 50.0, 1.5);  // PIP's range starts at −10°
    EXPECT_EQ(where.rfind("index PIP flexion", 0), 0u) << where;
    // Middle MCP (joint 3) turned 45° about the palm normal: abduction 45°, 20° too many.
    Eigen::VectorXd spread = Eigen::VectorXd::Zero(45);
    const Eigen::Vector3d flex3 = procedural_digit_pose(static_cast<HandSide>(side), {1, 1, 1, 1, 1}, {0, 0, 0, 0, 0})
                                      .segment<3>(9)
                                      .normalized();
    // The palm normal: perpendicular to the flexion axis and to the bone.
    const Eigen::Vector3d normal = flex3.cross(bone_of(L, 3)).normalized();
    spread.segment<3>(9) = 45.0 / kDeg * normal;
    EXPECT_NEAR(std::abs(L.angles(3, spread.segment<3>(9))[1]), 45.0, 0.5);
    EXPECT_NEAR(L.largest_excess(spread, &where), 20.0, 0.5);
    EXPECT_EQ(where.rfind("middle MCP abduction", 0), 0u) << where;
    // Ring DIP (joint 11) twisted 50° about its bone: 30° beyond ±20°.
    Eigen::VectorXd twisted = Eigen::VectorXd::Zero(45);
    twisted.segment<3>(33) = 50.0 / kDeg * bone_of(L, 11);
    EXPECT_NEAR(L.angles(11, twisted.segment<3>(33))[2], 50.0, 0.5);
    EXPECT_NEAR(L.largest_excess(twisted, &where), 30.0, 0.5);
    EXPECT_EQ(where.rfind("ring DIP twist", 0), 0u) << where;
    // The same rotation wound once more (θ − 2π about the same axis): the same angles.
    Eigen::VectorXd wound = twisted;
    wound.segment<3>(33) = (50.0 / kDeg - 2 * M_PI) * bone_of(L, 11);
    EXPECT_NEAR(L.angles(11, wound.segment<3>(33))[2], 50.0, 0.5);
    EXPECT_NEAR(L.largest_excess(wound), 30.0, 0.5);
    // The thumb's IP swung 120°: 25° beyond 95°.
    Eigen::VectorXd thumb = Eigen::VectorXd::Zero(45);
    thumb.segment<3>(42) = 120.0 / kDeg * bone_of(L, 14).unitOrthogonal();  // an axis across the bone
    EXPECT_NEAR(L.angles(14, thumb.segment<3>(42))[0], 120.0, 0.5);
    EXPECT_NEAR(L.largest_excess(thumb, &where), 25.0, 0.5);
    EXPECT_EQ(where.rfind("thumb IP swing", 0), 0u) << where;
  }
}

// clamp() puts every joint on its range's edge and leaves the angles inside alone.
TEST(JointLimits, ClampMovesAJointOntoItsRangeAndNoFurther) {
  for (int side : {0, 1}) {
    const JointLimits L(hand(side));
    const Eigen::VectorXd curled = procedural_digit_pose(static_cast<HandSide>(side), {0.4, 0.4, 0.4, 0.4, 0.4},
                                                         {0, 0, 0, 0, 0});
    Eigen::VectorXd pose = curled;
    EXPECT_EQ(L.clamp_pose(pose.data()), 0);
    EXPECT_EQ((pose - curled).norm(), 0.0);
    // Index PIP bent 60° backwards and twisted 35°: flexion −10° (its edge), twist 20°.
    const Eigen::Vector3d flex_axis = curled.segment<3>(3).normalized();
    const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::AngleAxisd(-60.0 / kDeg, flex_axis)) *
                                 Eigen::Quaterniond(Eigen::AngleAxisd(35.0 / kDeg, bone_of(L, 1)));
    const Eigen::AngleAxisd r(q);
    Eigen::Vector3d aa = r.angle() * r.axis();
    const Eigen::Vector3d before = L.angles(1, aa);
    EXPECT_NEAR(before[0], -60.0, 1.0);
    EXPECT_NEAR(before[2], 35.0, 1.0);
    EXPECT_TRUE(L.clamp(1, &aa));
    const Eigen::Vector3d after = L.angles(1, aa);
    EXPECT_NEAR(after[0], kAnatomicalLimits.pip.flex.lo, 1e-6);
    EXPECT_NEAR(after[1], before[1], 1e-6);
    EXPECT_NEAR(after[2], kAnatomicalLimits.pip.twist.hi, 1e-6);
    // Random poses, wound past π as a solver may leave them: all inside after the clamp.
    std::mt19937 rng(5 + side);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    for (int trial = 0; trial < 50; ++trial) {
      Eigen::VectorXd p(45);
      for (int i = 0; i < 45; ++i) p[i] = u(rng);
      L.clamp_pose(p.data());
      std::string where;
      EXPECT_LT(L.largest_excess(p, &where), 1e-6) << where;
    }
  }
}

// The refinement's angles: rotation() and parameters() are inverses, the fingers' angles
// are those angles() reads, every rotation inside the box is inside the ranges (up to the
// thumb's 80° corners, which clamp() takes), and rotation()'s Jets match numeric derivatives.
TEST(JointLimits, BoundedAnglesRoundTripAndStayInsideTheRanges) {
  using Jet = ceres::Jet<double, 3>;
  for (int side : {0, 1}) {
    const JointLimits L(hand(side));
    std::mt19937 rng(11 + side);
    std::uniform_real_distribution<double> unit(0.0, 1.0), u(-2.5, 2.5);
    for (int trial = 0; trial < 300; ++trial) {
      const int j = trial % 15;
      const auto box = L.bounds(j);
      Eigen::Vector3d angle;
      for (int c = 0; c < 3; ++c) angle[c] = box[c].lo + unit(rng) * (box[c].hi - box[c].lo);
      Eigen::Vector3d aa;
      L.rotation(j, angle.data(), aa.data());
      EXPECT_LT((L.parameters(j, aa) - angle).norm(), 1e-9) << "joint " << j;
      if (j < 12) {
        EXPECT_LT((L.angles(j, aa) - angle * kDeg).norm(), 1e-7) << "joint " << j;
        double r[3];
        L.excess(j, aa.data(), r);
        EXPECT_LT(Eigen::Vector3d(r[0], r[1], r[2]).norm(), 1e-9) << "joint " << j;
      } else if (j != 13) {  // the thumb's CMC (90°) and IP (95°): the box is inside the disc
        EXPECT_LE(L.angles(j, aa)[0], box[0].hi * kDeg + 1e-7) << "joint " << j;
      }
      // Any rotation under π round-trips (as a rotation) through parameters().
      Eigen::Vector3d any(u(rng), u(rng), u(rng));
      if (any.norm() > 3.0) any *= 3.0 / any.norm();
      const Eigen::Vector3d p = L.parameters(j, any);
      Eigen::Vector3d back;
      L.rotation(j, p.data(), back.data());
      const Eigen::Quaterniond qa(Eigen::AngleAxisd(any.norm(), any.normalized())),
          qb(Eigen::AngleAxisd(back.norm(), back.normalized()));
      EXPECT_GT(std::abs(qa.dot(qb)), 1 - 1e-10) << "joint " << j;
      // Jets against central differences.
      const Jet x[3] = {Jet(angle[0], 0), Jet(angle[1], 1), Jet(angle[2], 2)};
      Jet r[3];
      L.rotation(j, x, r);
      for (int q = 0; q < 3; ++q) {
        constexpr double h = 1e-6;
        Eigen::Vector3d lo = angle, hi = angle, rl, rh;
        lo[q] -= h;
        hi[q] += h;
        L.rotation(j, lo.data(), rl.data());
        L.rotation(j, hi.data(), rh.data());
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(r[c].v[q], (rh[c] - rl[c]) / (2 * h), 1e-6) << "joint " << j;
      }
    }
    // The rest pose is the origin of the angles.
    for (int j = 0; j < 15; ++j) EXPECT_LT(L.parameters(j, Eigen::Vector3d::Zero()).norm(), 1e-12);
  }
}

TEST(JointLimits, JetDerivativesMatchNumericOnes) {
  using Jet = ceres::Jet<double, 3>;
  const JointLimits L(hand(1));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int j = trial % 15;
    const Eigen::Vector3d aa(u(rng), u(rng), u(rng));
    Jet x[3] = {Jet(aa[0], 0), Jet(aa[1], 1), Jet(aa[2], 2)};
    Jet r[3];
    L.excess(j, x, r);
    for (int c = 0; c < 3; ++c) {
      constexpr double h = 1e-6;
      for (int p = 0; p < 3; ++p) {
        Eigen::Vector3d lo = aa, hi = aa;
        lo[p] -= h;
        hi[p] += h;
        double rl[3], rh[3];
        L.excess(j, lo.data(), rl);
        L.excess(j, hi.data(), rh);
        if ((rl[c] == 0) != (rh[c] == 0)) continue;  // at a range's edge
        EXPECT_NEAR(r[c].v[p], (rh[c] - rl[c]) / (2 * h), 1e-5) << "joint " << j << " angle " << c;
        ++checked;
      }
      EXPECT_NEAR(r[c].a, [&] {
        double rr[3];
        L.excess(j, aa.data(), rr);
        return rr[c];
      }(), 1e-12);
    }
  }
  EXPECT_GT(checked, 1000);
}

}  // namespace
}  // namespace bimart
