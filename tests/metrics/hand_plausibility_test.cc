// The hand-plausibility measure (core/metrics/hand_plausibility.h) on the shipped hands:
// the flat hand and a grasp pass, a finger bent backwards and two fingers crossed are
// flagged (both hands: the left is the mirror image), and the frame count over posed
// vertices names the first bad frame.
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include <CGAL/Simple_cartesian.h>
#include <CGAL/squared_distance_3.h>

#include <cmath>
#include <random>

#include "core/hand/finger_separation.h"
#include "core/hand/lbs.h"
#include "core/metrics/hand_plausibility.h"
#include "core/synth/grasp.h"
#include "tests/synth/shipped_hands.h"

namespace bimart {
namespace {

struct Posed {
  Eigen::Matrix<double, 16, 3> joints;
  Eigen::Matrix<double, 5, 3> tips;
  LbsResult<double> r;
};

Posed pose(int hand, const Eigen::VectorXd& fingers) {
  const HandModel& m = *test::shipped_hands()[static_cast<std::size_t>(hand)];
  Posed p;
  p.r = lbs<double>(m, Eigen::Vector3d(0.3, -0.2, 0.1), fingers, Eigen::Vector3d(0.1, 0.2, 0.3),
                    Eigen::VectorXd::Zero(HandModel::kNumBetas));
  p.joints = m.j_regressor * p.r.vertices;  // as the measure gets them: regressed from the vertices
  for (int f = 0; f < 5; ++f) p.tips.row(f) = p.r.vertices.row(m.fingertips[static_cast<std::size_t>(f)]);
  return p;
}

// A finger pose with `aa` (right-hand axis-angle) at joint `j` (1..15), mirrored for the left.
Eigen::VectorXd with_joint(int hand, int j, Eigen::Vector3d aa) {
  if (hand == 0) aa = Eigen::Vector3d(aa.x(), -aa.y(), -aa.z());
  Eigen::VectorXd p = Eigen::VectorXd::Zero(45);
  p.segment<3>(3 * (j - 1)) = aa;
  return p;
}

TEST(HandPlausibility, FlatHandAndAGraspPassBentBackAndCrossedFingersDoNot) {
  for (int h = 0; h < 2; ++h) {
    const Posed flat = pose(h, Eigen::VectorXd::Zero(45));
    EXPECT_EQ(implausibility(flat.joints, flat.tips, h), "") << h;
    // A firm grasp of the synthetic engine (every digit curled 0.9 of a loose fist).
    const HandGeometry geo = hand_geometry(*test::shipped_hands()[static_cast<std::size_t>(h)], Eigen::VectorXd::Zero(10));
    const Posed grasp = pose(h, grasp_finger_pose(geo, {0.9, 0.9, 0.9, 0.9, 0.9}, 0.0));
    EXPECT_EQ(implausibility(grasp.joints, grasp.tips, h), "") << h;
    // The index PIP (joint 2) bent 60° backwards: flexion is + about +z on the right hand.
    const Posed back = pose(h, with_joint(h, 2, Eigen::Vector3d(0, 0, -1.05)));
    const std::string why = implausibility(back.joints, back.tips, h);
    EXPECT_NE(why.find("index PIP flexion -"), std::string::npos) << h << ": " << why;
    // ... and 60° forwards is fine.
    const Posed fwd = pose(h, with_joint(h, 2, Eigen::Vector3d(0, 0, 1.05)));
    EXPECT_EQ(implausibility(fwd.joints, fwd.tips, h), "") << h;
    // The index MCP flexed 80° towards the palm with 12° of abduction is fine (read about the
    // palm normal, as the measure first did, it read 45°, on the range's edge); spread 60° in the
    // palm's plane is not.
    const auto turned = [](double flex_deg, double abduct_deg) {
      const Eigen::AngleAxisd r(Eigen::AngleAxisd(flex_deg * M_PI / 180, Eigen::Vector3d::UnitZ()) *
                                Eigen::AngleAxisd(abduct_deg * M_PI / 180, Eigen::Vector3d::UnitY()));
      return Eigen::Vector3d(r.angle() * r.axis());
    };
    const Posed flexed = pose(h, with_joint(h, 1, turned(80, 12)));
    EXPECT_EQ(implausibility(flexed.joints, flexed.tips, h), "") << h;
    const Posed spread = pose(h, with_joint(h, 1, turned(0, 60)));
    EXPECT_NE(implausibility(spread.joints, spread.tips, h).find("index MCP abduction"), std::string::npos) << h;
    // Index and middle spread 20° towards each other at their MCP (within the abduction
    // range each): they cross.
    Eigen::VectorXd cross = with_joint(h, 1, Eigen::Vector3d(0, -0.35, 0));
    cross += with_joint(h, 4, Eigen::Vector3d(0, 0.35, 0));
    const Posed crossed = pose(h, cross);
    EXPECT_EQ(implausibility(crossed.joints, crossed.tips, h), "index and middle cross") << h;
  }
}

TEST(HandPlausibility, FramesOfPosedVerticesCountAFrameWithOneBadHand) {
  const Posed ok = pose(1, Eigen::VectorXd::Zero(45)), bad = pose(1, with_joint(1, 2, Eigen::Vector3d(0, 0, -1.05)));
  const Posed left = pose(0, Eigen::VectorXd::Zero(45));
  const auto V = ok.r.vertices.rows();
  at::Tensor v = at::empty({2, 3, V, 3}, at::kDouble);
  for (int t = 0; t < 3; ++t) {
    std::copy(left.r.vertices.data(), left.r.vertices.data() + 3 * V, v[0][t].data_ptr<double>());
    const auto& right = t == 1 ? bad.r.vertices : ok.r.vertices;
    std::copy(right.data(), right.data() + 3 * V, v[1][t].data_ptr<double>());
  }
  std::string why;
  const FrameCount c = implausible_frames(v, test::shipped_hands(), &why);
  EXPECT_EQ(c.frames, 3);
  EXPECT_EQ(c.hits, 1);
  EXPECT_NE(why.find("frame 1, right hand: index PIP"), std::string::npos) << why;
}

// The separation term's segment distance (written out for Ceres Jets) against CGAL's, which
// the measure uses: random segments, including parallel ones and ones that cross.
TEST(FingerSeparation, SegmentDistanceAgreesWithCgal) {
  using K = CGAL::Simple_cartesian<double>;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    double p0[3], p1[3], q0[3], q1[3];
    for (int k = 0; k < 3; ++k) {
      p0[k] = u(rng), p1[k] = u(rng), q0[k] = u(rng), q1[k] = u(rng);
    }
    if (i % 4 == 1)  // parallel
      for (int k = 0; k < 3; ++k) q1[k] = q0[k] + 0.7 * (p1[k] - p0[k]);
    if (i % 4 == 2)  // crossing: q passes through p's midpoint
      for (int k = 0; k < 3; ++k) q1[k] = 2 * (0.5 * (p0[k] + p1[k])) - q0[k];
    const K::Segment_3 a(K::Point_3(p0[0], p0[1], p0[2]), K::Point_3(p1[0], p1[1], p1[2]));
    const K::Segment_3 b(K::Point_3(q0[0], q0[1], q0[2]), K::Point_3(q1[0], q1[1], q1[2]));
    const double expected = std::sqrt(CGAL::to_double(CGAL::squared_distance(a, b)));
    worst = std::max(worst, std::abs(segment_distance(p0, p1, q0, q1) - expected));
  }
  EXPECT_LT(worst, 1e-8);  // m (the 1e-18 m² under the root: 1e-9 m where the segments meet)
}

// Shortfall and measure agree: a grasp keeps every pair apart (all zero), fingers crossed
// as the measure's test crosses them leave a pair short by more than the gap minus the
// measure's threshold.
TEST(FingerSeparation, ShortfallIsZeroForAGraspAndPositiveForCrossedFingers) {
  for (int h = 0; h < 2; ++h) {
    const HandModel& m = *test::shipped_hands()[static_cast<std::size_t>(h)];
    const auto shortfall = [&](const Eigen::VectorXd& fingers) {
      const Posed p = pose(h, fingers);
      double J[16][3], tips[5][3], r[kFingerSeparationResiduals];
      for (int j = 0; j < 16; ++j)
        for (int k = 0; k < 3; ++k) J[j][k] = p.joints(j, k);  // regressed, as the measure
      for (int f = 0; f < 5; ++f)
        for (int k = 0; k < 3; ++k) tips[f][k] = p.tips(f, k);
      finger_separation_shortfall<double>(J, tips, kFingerSeparation, r);
      return *std::max_element(r, r + kFingerSeparationResiduals);
    };
    EXPECT_EQ(shortfall(Eigen::VectorXd::Zero(45)), 0.0) << "flat hand " << h;
    const HandGeometry geo = hand_geometry(m, Eigen::VectorXd::Zero(10));
    EXPECT_EQ(shortfall(grasp_finger_pose(geo, {0.9, 0.9, 0.9, 0.9, 0.9}, 0.0)), 0.0) << "grasp " << h;
    Eigen::VectorXd cross = with_joint(h, 1, Eigen::Vector3d(0, -0.35, 0));
    cross += with_joint(h, 4, Eigen::Vector3d(0, 0.35, 0));
    EXPECT_GT(shortfall(cross), kFingerSeparation - kCrossedGap) << "crossed " << h;
  }
}

}  // namespace
}  // namespace bimart
