#include "core/hand/lbs.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Geometry>

#include "tests/hand/synthetic_model.h"

namespace bimart {
namespace {

using RowMat3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

// All 61 inputs of one hand: rot (3), pose (45), trans (3), betas (10).
struct Params {
  Eigen::Matrix<double, 61, 1> x = Eigen::Matrix<double, 61, 1>::Zero();
  const double* rot() const { return x.data(); }
  const double* pose() const { return x.data() + 3; }
  const double* trans() const { return x.data() + 48; }
  const double* betas() const { return x.data() + 51; }
};

Params random_params(std::mt19937& rng, double angle = 0.6) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Params p;
  for (int i = 0; i < 48; ++i) p.x[i] = angle * u(rng);
  for (int i = 48; i < 51; ++i) p.x[i] = 0.3 * u(rng);
  for (int i = 51; i < 61; ++i) p.x[i] = 2.0 * u(rng);
  return p;
}

LbsResult<double> run(const HandModel& m, const Params& p) {
  LbsResult<double> out;
  lbs(m, p.rot(), p.pose(), p.trans(), p.betas(), &out);
  return out;
}

Eigen::Matrix3d rotation(const Eigen::Vector3d& aa) {
  const double a = aa.norm();
  return a == 0 ? Eigen::Matrix3d::Identity() : Eigen::AngleAxisd(a, aa / a).toRotationMatrix();
}

TEST(AxisAngleTest, MatchesEigenIncludingTinyAngles) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double scale : {3.0, 1.0, 1e-3, 1e-4, 1e-5, 1e-7, 1e-12, 0.0}) {
    for (int t = 0; t < 5; ++t) {
      const Eigen::Vector3d aa = scale * Eigen::Vector3d(u(rng), u(rng), u(rng));
      Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R;
      axis_angle_to_matrix(aa.data(), R.data());
      EXPECT_LT((R - rotation(aa)).cwiseAbs().maxCoeff(), 1e-15) << "scale " << scale;
      EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
    }
  }
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R;
  const double zero[3] = {0, 0, 0};
  axis_angle_to_matrix(zero, R.data());
  EXPECT_EQ(R, Eigen::Matrix3d::Identity());  // exactly
}

TEST(LbsTest, ZeroPoseAndShapeReproduceTheTemplate) {
  const HandModel m = testing::make_synthetic_hand(50);
  const LbsResult<double> r = run(m, Params{});
  // Rounding only: the blend of identity transforms sums the weights.
  EXPECT_LT((r.vertices - m.v_template).cwiseAbs().maxCoeff(), 1e-15);
  const RowMat3 J = m.j_regressor * m.v_template;
  EXPECT_LT((r.joints - J).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(LbsTest, ShapeOnlyAddsShapeBlendShapes) {
  const HandModel m = testing::make_synthetic_hand(50);
  std::mt19937 rng(2);
  Params p = random_params(rng);
  p.x.head(51).setZero();
  const LbsResult<double> r = run(m, p);
  const Eigen::VectorXd offsets = m.shapedirs * p.x.tail(10);
  const RowMat3 shaped = m.v_template + Eigen::Map<const RowMat3>(offsets.data(), 50, 3);
  EXPECT_LT((r.vertices - shaped).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((r.joints - RowMat3(m.j_regressor * shaped)).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(LbsTest, GlobalRotationIsRigidAboutTheRootJointAndTranslationIsAdded) {
  const HandModel m = testing::make_synthetic_hand(50);
  std::mt19937 rng(3);
  Params p = random_params(rng);
  const Eigen::Vector3d rot(p.x[0], p.x[1], p.x[2]), trans(p.x[48], p.x[49], p.x[50]);
  Params still = p;
  still.x.head(3).setZero();
  still.x.segment(48, 3).setZero();
  const LbsResult<double> a = run(m, still), b = run(m, p);
  const Eigen::RowVector3d j0 = a.joints.row(0);
  const Eigen::Matrix3d R = rotation(rot);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d want = R * (a.vertices.row(i) - j0).transpose() + j0.transpose() + trans;
    EXPECT_LT((b.vertices.row(i).transpose() - want).norm(), 1e-14) << "vertex " << i;
  }
  for (int j = 0; j < 16; ++j) {
    const Eigen::Vector3d want = R * (a.joints.row(j) - j0).transpose() + j0.transpose() + trans;
    EXPECT_LT((b.joints.row(j).transpose() - want).norm(), 1e-14) << "joint " << j;
  }
}

// A vertex bound to index2 (joint 2, child of joint 1): posing joints 1 and 2 moves it by
// the composed rotations about the two rest joints.
TEST(LbsTest, FingerJointsComposeAlongTheChain) {
  HandModel m = testing::make_synthetic_hand(50);
  m.posedirs.setZero();
  m.weights.row(0).setZero();
  m.weights(0, 2) = 1.0;
  Params p;
  const Eigen::Vector3d r1(0.3, -0.5, 0.2), r2(-0.7, 0.1, 0.4);
  p.x.segment<3>(3) = r1;  // joint 1
  p.x.segment<3>(6) = r2;  // joint 2
  const LbsResult<double> r = run(m, p);
  const RowMat3 J = m.j_regressor * m.v_template;
  const Eigen::Vector3d v = m.v_template.row(0).transpose();
  const Eigen::Vector3d J1 = J.row(1).transpose(), J2 = J.row(2).transpose();
  const Eigen::Vector3d want = rotation(r1) * (rotation(r2) * (v - J2) + J2 - J1) + J1;
  EXPECT_LT((r.vertices.row(0).transpose() - want).norm(), 1e-15);
  EXPECT_LT((r.joints.row(2).transpose() - (rotation(r1) * (J2 - J1) + J1)).norm(), 1e-15);
}

// Pose correctives: feature = (R_j − I) row-major for joints 1..15, times posedirs.
TEST(LbsTest, PoseCorrectivesFollowTheManoFeature) {
  HandModel m = testing::make_synthetic_hand(50);
  m.weights.setZero();
  m.weights.col(0).setOnes();  // all on the wrist: rot = 0 leaves only the correctives
  Params p;
  const Eigen::Vector3d r5(0.4, 0.2, -0.3);
  p.x.segment<3>(3 + 3 * 4) = r5;  // joint 5 -> feature entries 36..44
  const LbsResult<double> r = run(m, p);
  Eigen::VectorXd feature = Eigen::VectorXd::Zero(135);
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> D = rotation(r5) - Eigen::Matrix3d::Identity();
  feature.segment<9>(36) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(D.data());
  const Eigen::VectorXd offsets = m.posedirs * feature;
  const RowMat3 want = m.v_template + Eigen::Map<const RowMat3>(offsets.data(), 50, 3);
  EXPECT_LT((r.vertices - want).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(LbsTest, Keypoints21AreJointsThenFingertips) {
  const HandModel m = testing::make_synthetic_hand(50);
  std::mt19937 rng(4);
  const LbsResult<double> r = run(m, random_params(rng));
  const auto k = keypoints21(m, r);
  for (int j = 0; j < 16; ++j) EXPECT_EQ(k.row(j), r.joints.row(j));
  for (int i = 0; i < 5; ++i) EXPECT_EQ(k.row(16 + i), r.vertices.row(m.fingertips[i]));
}

// Jet derivatives of every output against central differences, at a random pose and at
// the zero pose (where the axis-angle uses its Taylor branch).
TEST(LbsTest, JetDerivativesMatchCentralDifferences) {
  using Jet = ceres::Jet<double, 61>;
  const HandModel m = testing::make_synthetic_hand(30);
  std::mt19937 rng(5);
  for (const Params& p : {random_params(rng), Params{}}) {
    std::vector<Jet> x(61);
    for (int i = 0; i < 61; ++i) x[i] = Jet(p.x[i], i);
    LbsResult<Jet> rj;
    lbs(m, &x[0], &x[3], &x[48], &x[51], &rj);
    const LbsResult<double> r0 = run(m, p);

    const double h = 1e-6;
    double worst = 0;
    for (int i = 0; i < 61; ++i) {
      Params plus = p, minus = p;
      plus.x[i] += h;
      minus.x[i] -= h;
      const LbsResult<double> a = run(m, plus), b = run(m, minus);
      for (int v = 0; v < 30; ++v)
        for (int k = 0; k < 3; ++k) {
          const double fd = (a.vertices(v, k) - b.vertices(v, k)) / (2 * h);
          worst = std::max(worst, std::abs(rj.vertices(v, k).v[i] - fd));
        }
      for (int j = 0; j < 16; ++j)
        for (int k = 0; k < 3; ++k) {
          const double fd = (a.joints(j, k) - b.joints(j, k)) / (2 * h);
          worst = std::max(worst, std::abs(rj.joints(j, k).v[i] - fd));
        }
    }
    EXPECT_LT(worst, 1e-8);
    // Values agree with the double version to rounding.
    for (int v = 0; v < 30; ++v)
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(rj.vertices(v, k).a, r0.vertices(v, k), 1e-14);
  }
}

TEST(PoseConversionTest, MeanRelativeAndPcaRoundTrip) {
  const HandModel m = testing::make_synthetic_hand(20);
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd flat(45);
  for (int i = 0; i < 45; ++i) flat[i] = u(rng);
  EXPECT_LT((flat_pose_from_mean_relative(m, mean_relative_from_flat_pose(m, flat)) - flat)
                .cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(mean_relative_from_flat_pose(m, m.hands_mean), Eigen::VectorXd::Zero(45));

  // All 45 components: exact both ways.
  const Eigen::VectorXd c45 = pca_from_flat_pose(m, flat, 45);
  EXPECT_LT((flat_pose_from_pca(m, c45) - flat).cwiseAbs().maxCoeff(), 1e-13);
  // 12 components (a common setting): a pose in their span comes back to its coefficients.
  Eigen::VectorXd c12(12);
  for (int i = 0; i < 12; ++i) c12[i] = u(rng);
  const Eigen::VectorXd from12 = flat_pose_from_pca(m, c12);
  EXPECT_LT((pca_from_flat_pose(m, from12, 12) - c12).cwiseAbs().maxCoeff(), 1e-13);
  // MANO's definition: mean + Σ c_i · component_i.
  Eigen::VectorXd want = m.hands_mean;
  for (int i = 0; i < 12; ++i) want += c12[i] * m.hands_components.row(i).transpose();
  EXPECT_LT((from12 - want).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_EQ(flat_pose_from_pca(m, Eigen::VectorXd()), m.hands_mean);
}

}  // namespace
}  // namespace bimart
