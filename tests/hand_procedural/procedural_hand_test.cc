#include "core/hand/procedural_hand.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include <Eigen/Geometry>

#include "core/hand/keypoints.h"
#include "core/hand/lbs.h"
#include "core/hand/procedural_hand_mesh.h"
#include "tests/hand_procedural/fixture.h"

namespace bimart {
namespace {

using Verts = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
constexpr int kThumbTip = 0, kIndexTip = 1, kMiddleTip = 2, kRingTip = 3, kPinkyTip = 4;

// Vertices and regressed joints for a shape.
struct Shaped {
  Verts v;
  Eigen::Matrix<double, 16, 3> J;
  Eigen::Vector3d joint(int j) const { return J.row(j).transpose(); }
  Eigen::Vector3d vert(int i) const { return v.row(i).transpose(); }
};

Shaped shaped(const HandModel& m, const Eigen::VectorXd& beta) {
  Shaped s;
  const Eigen::VectorXd flat = m.shapedirs * beta;
  s.v = m.v_template + Eigen::Map<const Verts>(flat.data(), m.num_vertices(), 3);
  s.J = m.j_regressor * s.v;
  return s;
}

Eigen::VectorXd unit_beta(int k, double value = 1.0) {
  Eigen::VectorXd b = Eigen::VectorXd::Zero(10);
  b[k] = value;
  return b;
}

const Eigen::VectorXd kMean = Eigen::VectorXd::Zero(10);

double hand_length(const HandModel& m, const Shaped& s) { return (s.vert(m.fingertips[kMiddleTip]) - s.joint(0)).norm(); }
double middle_length(const HandModel& m, const Shaped& s) { return (s.vert(m.fingertips[kMiddleTip]) - s.joint(4)).norm(); }
double knuckle_span(const Shaped& s) { return (s.joint(1) - s.joint(7)).norm(); }  // index1 to pinky1

TEST(ProceduralHand, SurfaceIsClosedManifoldAndFreeOfSelfIntersections) {
  for (const HandModel* m : {&test::right_hand(), &test::left_hand()}) {
    EXPECT_GE(m->num_vertices(), 700);
    EXPECT_LE(m->num_vertices(), 900);
    const SurfaceCheck c = check_surface(TriangleMesh{m->v_template, m->faces});
    EXPECT_TRUE(c.manifold);
    EXPECT_TRUE(c.closed);
    EXPECT_FALSE(c.self_intersecting);
    EXPECT_TRUE(c.outward);
    // Closed and genus 0: V - E + F = 2 with E = 3F/2.
    EXPECT_EQ(m->num_vertices() - m->num_faces() / 2, 2);
  }
}

TEST(ProceduralHand, AdultDimensions) {
  const HandModel& m = test::right_hand();
  const Shaped s = shaped(m, kMean);
  EXPECT_NEAR(hand_length(m, s), 0.186, 0.004);  // wrist joint to middle fingertip
  // Palm breadth skin to skin (z in MANO's right frame) in a 1 cm slab at the knuckle row,
  // thumb left out.
  const std::vector<int> part = hand_parts(m);
  const double knuckles_x = 0.5 * (s.J(1, 0) + s.J(7, 0));
  double lo = 1, hi = -1;
  for (int v = 0; v < m.num_vertices(); ++v)
    if (part[v] < 13 && std::abs(m.v_template(v, 0) - knuckles_x) < 0.005)
      lo = std::min(lo, m.v_template(v, 2)), hi = std::max(hi, m.v_template(v, 2));
  EXPECT_NEAR(hi - lo, 0.085, 0.006);
}

TEST(ProceduralHand, MANOJointOrderParentsAndFrame) {
  const HandModel& m = test::right_hand();
  const std::array<int, 16> mano{-1, 0, 1, 2, 0, 4, 5, 0, 7, 8, 0, 10, 11, 0, 13, 14};
  EXPECT_EQ(m.parents, mano);
  const Shaped s = shaped(m, kMean);
  // Knuckles from the thumb side (+z) across: index, middle, ring, pinky.
  EXPECT_GT(s.J(1, 2), s.J(4, 2));
  EXPECT_GT(s.J(4, 2), s.J(10, 2));
  EXPECT_GT(s.J(10, 2), s.J(7, 2));
  // Fingers point along -x, each chain going further out.
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) EXPECT_LT(s.J(1 + 3 * c + k, 0), (k == 0 ? s.J(0, 0) : s.J(3 * c + k, 0)) - 0.015);
  // The thumb is on the +z side and out of the palm plane towards the palm (-y).
  EXPECT_GT(s.vert(m.fingertips[kThumbTip]).z(), s.vert(m.fingertips[kIndexTip]).z() + 0.03);
  EXPECT_LT(s.J(14, 1), s.J(0, 1) - 0.01);
  // The middle fingertip vertex is the furthest-out vertex along -x.
  Eigen::Index far;
  m.v_template.col(0).minCoeff(&far);
  EXPECT_EQ(far, m.fingertips[kMiddleTip]);
}

TEST(ProceduralHand, RegressorReproducesTheSkeleton) {
  const HandModel& m = test::right_hand();
  const HandSkeleton sk = procedural_hand_skeleton(HandSide::Right);
  const Shaped s = shaped(m, kMean);
  for (int j = 0; j < 16; ++j) EXPECT_LT((s.joint(j) - sk.joints[j]).norm(), 1e-3) << "joint " << j;
  for (int t = 0; t < 5; ++t) EXPECT_LT((s.vert(m.fingertips[t]) - sk.tips[t]).norm(), 4e-3) << "tip " << t;
  // Shapes move the regressed joints with the skeleton.
  for (int k = 0; k < 10; ++k) {
    const HandSkeleton shaped_sk = procedural_hand_skeleton(HandSide::Right, unit_beta(k));
    const Shaped sb = shaped(m, unit_beta(k));
    for (int j = 0; j < 16; ++j)
      EXPECT_LT((sb.joint(j) - shaped_sk.joints[j]).norm(), 2.5e-3) << procedural_shape_names()[k] << " joint " << j;
  }
}

TEST(ProceduralHand, SkinningWeightsAreNormalisedAndLocal) {
  const HandModel& m = test::right_hand();
  EXPECT_LT((m.weights.rowwise().sum().array() - 1.0).abs().maxCoeff(), 1e-12);
  EXPECT_GE(m.weights.minCoeff(), 0.0);
  // Every joint dominates some vertices; the middle fingertip moves with the middle's end joint.
  const std::vector<int> part = hand_parts(m);
  for (int j = 0; j < 16; ++j) EXPECT_GT(std::count(part.begin(), part.end(), j), 5) << "joint " << j;
  EXPECT_GT(m.weights(m.fingertips[kMiddleTip], 6), 0.9);
  EXPECT_GT(m.weights(m.fingertips[kThumbTip], 15), 0.9);
}

TEST(ProceduralHand, EachShapeDirectionChangesWhatItClaims) {
  const HandModel& m = test::right_hand();
  const Shaped s0 = shaped(m, kMean);
  auto rel = [](double after, double before) { return after / before - 1; };
  {  // 0 size: everything +10 %
    const Shaped s = shaped(m, unit_beta(0));
    EXPECT_NEAR(rel(hand_length(m, s), hand_length(m, s0)), 0.10, 0.01);
    EXPECT_NEAR(rel(knuckle_span(s), knuckle_span(s0)), 0.10, 0.01);
  }
  {  // 1 palm width: the knuckle span, not the finger lengths
    const Shaped s = shaped(m, unit_beta(1));
    EXPECT_NEAR(rel(knuckle_span(s), knuckle_span(s0)), 0.10, 0.015);
    EXPECT_LT(std::abs(rel(middle_length(m, s), middle_length(m, s0))), 0.01);
  }
  {  // 2 palm length: wrist to middle knuckle
    const Shaped s = shaped(m, unit_beta(2));
    EXPECT_NEAR(rel((s.joint(4) - s.joint(0)).norm(), (s0.joint(4) - s0.joint(0)).norm()), 0.10, 0.01);
    EXPECT_LT(std::abs(rel(middle_length(m, s), middle_length(m, s0))), 0.01);
  }
  {  // 3 finger length: the four fingers, not the palm or thumb
    const Shaped s = shaped(m, unit_beta(3));
    EXPECT_NEAR(rel((s.joint(6) - s.joint(4)).norm(), (s0.joint(6) - s0.joint(4)).norm()), 0.10, 0.01);
    EXPECT_GT(rel(middle_length(m, s), middle_length(m, s0)), 0.08);
    EXPECT_LT(std::abs(rel(knuckle_span(s), knuckle_span(s0))), 0.01);
    EXPECT_LT(std::abs(rel((s.joint(15) - s.joint(13)).norm(), (s0.joint(15) - s0.joint(13)).norm())), 0.01);
  }
  {  // 4 finger thickness: distance of the middle finger's middle-bone skin from its axis
    const Shaped s = shaped(m, unit_beta(4));
    const std::vector<int> part = hand_parts(m);
    double r0 = 0, r1 = 0;
    for (int v = 0; v < m.num_vertices(); ++v) {
      if (part[v] != 5) continue;
      auto dist = [&](const Shaped& x) {
        const Eigen::Vector3d a = x.joint(5), b = x.joint(6), p = x.vert(v);
        return (p - a).cross(b - a).norm() / (b - a).norm();
      };
      r0 += dist(s0), r1 += dist(s);
    }
    EXPECT_NEAR(rel(r1, r0), 0.12, 0.02);
    EXPECT_LT(std::abs(rel((s.joint(6) - s.joint(4)).norm(), (s0.joint(6) - s0.joint(4)).norm())), 0.01);
  }
  {  // 5 thumb length
    const Shaped s = shaped(m, unit_beta(5));
    EXPECT_NEAR(rel((s.joint(15) - s.joint(13)).norm(), (s0.joint(15) - s0.joint(13)).norm()), 0.10, 0.01);
    EXPECT_LT(std::abs(rel(middle_length(m, s), middle_length(m, s0))), 0.01);
  }
  {  // 6 index/ring: the ratio of the two fingers' lengths +7 %
    const Shaped s = shaped(m, unit_beta(6));
    auto ratio = [&](const Shaped& x) {
      return (x.vert(m.fingertips[kIndexTip]) - x.joint(1)).norm() / (x.vert(m.fingertips[kRingTip]) - x.joint(10)).norm();
    };
    EXPECT_NEAR(rel(ratio(s), ratio(s0)), 0.07, 0.015);
  }
  {  // 7 palm thickness: the palm's extent along y
    const Shaped s = shaped(m, unit_beta(7));
    const std::vector<int> part = hand_parts(m);
    auto thickness = [&](const Shaped& x) {
      double lo = 1, hi = -1;
      for (int v = 0; v < m.num_vertices(); ++v)
        if (part[v] == 0 && std::abs(x.v(v, 0) - x.J(0, 0) + 0.05) < 0.01) lo = std::min(lo, x.v(v, 1)), hi = std::max(hi, x.v(v, 1));
      return hi - lo;
    };
    EXPECT_NEAR(rel(thickness(s), thickness(s0)), 0.15, 0.03);
  }
  {  // 8 finger spread: index and pinky directions 12 degrees further apart
    const Shaped s = shaped(m, unit_beta(8));
    auto angle = [](const Shaped& x) {
      return std::acos((x.joint(2) - x.joint(1)).normalized().dot((x.joint(8) - x.joint(7)).normalized()));
    };
    EXPECT_NEAR((angle(s) - angle(s0)) * 180 / M_PI, 12.0, 1.0);
  }
  {  // 9 knuckle width: the knuckle row widens more than the wrist
    const Shaped s = shaped(m, unit_beta(9));
    EXPECT_NEAR(rel(knuckle_span(s), knuckle_span(s0)), 0.08, 0.015);
    auto wrist_width = [&](const Shaped& x) {
      double lo = 1, hi = -1;
      for (int v = 0; v < m.num_vertices(); ++v)
        if (std::abs(x.v(v, 0) - x.J(0, 0)) < 0.004) lo = std::min(lo, x.v(v, 2)), hi = std::max(hi, x.v(v, 2));
      return hi - lo;
    };
    EXPECT_LT(std::abs(rel(wrist_width(s), wrist_width(s0))), 0.01);
  }
}

TEST(ProceduralHand, LeftIsTheMirrorImageOfRight) {
  const HandModel &r = test::right_hand(), &l = test::left_hand();
  EXPECT_EQ(l.side, HandSide::Left);
  ASSERT_EQ(l.num_vertices(), r.num_vertices());
  Verts mirrored = r.v_template;
  mirrored.col(0) *= -1;
  EXPECT_LT((l.v_template - mirrored).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(l.faces.col(0), r.faces.col(0));
  EXPECT_EQ(l.faces.col(1), r.faces.col(2));
  EXPECT_EQ(l.faces.col(2), r.faces.col(1));
  for (int v = 0; v < r.num_vertices(); ++v) {
    EXPECT_EQ(l.shapedirs.row(3 * v), -r.shapedirs.row(3 * v));
    EXPECT_EQ(l.shapedirs.row(3 * v + 1), r.shapedirs.row(3 * v + 1));
  }
  EXPECT_EQ(l.weights, r.weights);
  EXPECT_EQ(l.j_regressor, r.j_regressor);
  EXPECT_EQ(l.fingertips, r.fingertips);
  EXPECT_EQ(l.parents, r.parents);
  // Poses mirror as (a, b, c) -> (a, -b, -c): a curled left hand is the mirrored curled right.
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  const Eigen::VectorXd betas = Eigen::VectorXd::Zero(10);
  const auto pr = lbs<double>(r, zero, procedural_curl_pose(HandSide::Right, 0.7, 0.5), zero, betas);
  const auto pl = lbs<double>(l, zero, procedural_curl_pose(HandSide::Left, 0.7, 0.5), zero, betas);
  Verts pr_mirrored = pr.vertices;
  pr_mirrored.col(0) *= -1;
  EXPECT_LT((pl.vertices - pr_mirrored).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(ProceduralHand, CurlPoseFlexesFingersTowardsThePalm) {
  const HandModel& m = test::right_hand();
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  const auto fist = lbs<double>(m, zero, procedural_curl_pose(HandSide::Right, 1.0, 0.8), zero, Eigen::VectorXd::Zero(10));
  const Shaped s0 = shaped(m, kMean);
  for (int t : {kIndexTip, kMiddleTip, kRingTip, kPinkyTip}) {
    const Eigen::Vector3d rest = s0.vert(m.fingertips[t]), curled = fist.vertices.row(m.fingertips[t]).transpose();
    EXPECT_LT(curled.y(), s0.J(0, 1) - 0.005) << "tip " << t;      // on the palm side
    EXPECT_GT(curled.x(), rest.x() + 0.06) << "tip " << t;          // pulled back towards the wrist
  }
}

TEST(ProceduralHand, PosePcaBasisIsOrthonormal) {
  const HandModel& m = test::right_hand();
  EXPECT_LT((m.hands_components * m.hands_components.transpose() - Eigen::MatrixXd::Identity(45, 45)).cwiseAbs().maxCoeff(), 1e-9);
  // The mean pose is a relaxed curl: positive flexion about +z at the middle finger's knuckle.
  EXPECT_GT(m.hands_mean[3 * 3 + 2], 0.3);
  EXPECT_TRUE(m.posedirs.isZero());
}

TEST(ProceduralHand, CheckedInModelsEqualAFreshHand) {
  for (const HandModel* fresh : {&test::right_hand(), &test::left_hand()}) {
    const std::string name = fresh->side == HandSide::Right ? "mano_right.npz" : "mano_left.npz";
    const HandModel m = load_hand_model(std::string(BIMART_SOURCE_DIR) + "/models/hand/" + name);
    EXPECT_EQ(m.side, fresh->side);
    ASSERT_EQ(m.num_vertices(), fresh->num_vertices()) << name;
    EXPECT_EQ(m.faces, fresh->faces);
    EXPECT_LT((m.v_template - fresh->v_template).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((m.shapedirs - fresh->shapedirs).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((m.j_regressor - fresh->j_regressor).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((m.weights - fresh->weights).cwiseAbs().maxCoeff(), 1e-12);
    // An eigensolver's vectors differ by round-off (~1e-11) between builds and CPUs.
    EXPECT_LT((m.hands_components - fresh->hands_components).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((m.hands_mean - fresh->hands_mean).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_EQ(m.fingertips, fresh->fingertips);
    EXPECT_EQ(m.keypoints, fresh->keypoints);
    EXPECT_EQ(m.parents, fresh->parents);
  }
}

}  // namespace
}  // namespace bimart
