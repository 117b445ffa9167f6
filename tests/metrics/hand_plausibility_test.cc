// The hand-plausibility measure (core/metrics/hand_plausibility.h) on the shipped hands:
// the flat hand and a grasp pass, a finger bent backwards and two fingers crossed are
// flagged (both hands: the left is the mirror image), and the frame count over posed
// vertices names the first bad frame.
#include <gtest/gtest.h>

#include <ATen/ATen.h>

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

}  // namespace
}  // namespace bimart
