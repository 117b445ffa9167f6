#include "core/geometry/rotation.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

namespace bimart {
namespace {

TEST(Rotation, ZeroIsIdentity) {
  EXPECT_EQ(axis_angle_to_matrix(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
  EXPECT_EQ(matrix_to_axis_angle(Eigen::Matrix3d::Identity()), Eigen::Vector3d::Zero());
}

TEST(Rotation, QuarterTurnAboutZ) {
  Eigen::Matrix3d expected;
  expected << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_TRUE(axis_angle_to_matrix(Eigen::Vector3d(0, 0, M_PI / 2)).isApprox(expected, 1e-15));
  // About -z the same angle turns the other way: -x goes to +y.
  const Eigen::Vector3d p = rotation_about(Eigen::Vector3d(0, 0, -1), M_PI / 2) * Eigen::Vector3d(-1, 0, 0);
  EXPECT_NEAR((p - Eigen::Vector3d(0, 1, 0)).norm(), 0, 1e-15);
}

TEST(Rotation, MatchesEigenAngleAxis) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const double angle = M_PI * (u(rng) + 1) / 2;
    const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    EXPECT_LT((axis_angle_to_matrix(angle * axis) - expected).norm(), 1e-14);
  }
}

TEST(Rotation, RoundTripIncludingTinyAndNearPi) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double angle : {1e-14, 1e-9, 1e-5, 0.3, 1.0, 2.5, M_PI - 1e-3, M_PI - 1e-7}) {
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d aa = angle * Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      const Eigen::Matrix3d R = axis_angle_to_matrix(aa);
      EXPECT_NEAR((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 0, 1e-14);
      EXPECT_NEAR(R.determinant(), 1, 1e-14);
      const Eigen::Vector3d back = matrix_to_axis_angle(R);
      // Relative accuracy for tiny angles; near pi the axis is only as good as the matrix.
      const double tol = angle < 1e-4 ? 1e-6 * angle : (angle > 3.14 ? 1e-6 : 1e-12);
      EXPECT_LT((back - aa).norm(), tol) << "angle " << angle;
      EXPECT_LT((axis_angle_to_matrix(back) - R).norm(), 1e-13);
    }
  }
}

TEST(Rotation, ExactlyPiGivesTheSameMatrix) {
  const Eigen::Vector3d aa = M_PI * Eigen::Vector3d(1, 2, -2).normalized();
  const Eigen::Matrix3d R = axis_angle_to_matrix(aa);
  const Eigen::Vector3d back = matrix_to_axis_angle(R);
  EXPECT_NEAR(back.norm(), M_PI, 1e-9);
  EXPECT_LT((axis_angle_to_matrix(back) - R).norm(), 1e-12);
}

TEST(Rotation, RotationBetween) {
  const Eigen::Vector3d a(1, 2, 3), b(-3, 0.5, 1);
  EXPECT_LT((rotation_between(a, b) * a.normalized() - b.normalized()).norm(), 1e-14);
  // Opposite directions: a half turn.
  const Eigen::Matrix3d R = rotation_between(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1));
  EXPECT_LT((R * Eigen::Vector3d(0, 0, 1) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-14);
  EXPECT_NEAR(R.determinant(), 1, 1e-14);
  EXPECT_EQ(rotation_between(a, 2 * a), Eigen::Matrix3d::Identity());
}

}  // namespace
}  // namespace bimart
