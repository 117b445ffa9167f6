#include "core/geometry/rotation.h"

#include <cmath>

#include <Eigen/Geometry>

namespace bimart {

Eigen::Matrix3d axis_angle_to_matrix(const Eigen::Vector3d& aa) {
  const double theta2 = aa.squaredNorm();
  Eigen::Matrix3d K;
  K << 0, -aa.z(), aa.y(), aa.z(), 0, -aa.x(), -aa.y(), aa.x(), 0;
  // R = I + a K + b K^2 with a = sin(t)/t, b = (1 - cos t)/t^2 (K built from the unnormalised
  // vector, so no division by t when t is tiny).
  double a, b;
  if (theta2 < 1e-12) {
    a = 1.0 - theta2 / 6.0;
    b = 0.5 - theta2 / 24.0;
  } else {
    const double theta = std::sqrt(theta2);
    a = std::sin(theta) / theta;
    b = (1.0 - std::cos(theta)) / theta2;
  }
  return Eigen::Matrix3d::Identity() + a * K + b * K * K;
}

Eigen::Vector3d matrix_to_axis_angle(const Eigen::Matrix3d& R) {
  // Eigen's matrix-to-quaternion conversion picks the numerically largest component, so it
  // stays accurate near pi where the trace formula loses the axis.
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d v = q.vec();
  const double s = v.norm();
  if (s < 1e-12) return 2.0 * v / q.w();  // angle ~ 2 s, axis v / s
  return 2.0 * std::atan2(s, q.w()) * v / s;
}

Eigen::Matrix3d rotation_about(const Eigen::Vector3d& axis, double angle) {
  return axis_angle_to_matrix(axis.normalized() * angle);
}

Eigen::Matrix3d rotation_between(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  const Eigen::Vector3d a = from.normalized(), b = to.normalized();
  const Eigen::Vector3d c = a.cross(b);
  const double s = c.norm(), d = a.dot(b);
  if (s < 1e-12) {
    if (d > 0) return Eigen::Matrix3d::Identity();
    // Opposite: any axis perpendicular to a; take the coordinate axis least aligned with a.
    Eigen::Index i;
    a.cwiseAbs().minCoeff(&i);
    const Eigen::Vector3d perp = a.cross(Eigen::Vector3d::Unit(i)).normalized();
    return rotation_about(perp, M_PI);
  }
  return axis_angle_to_matrix(c / s * std::atan2(s, d));
}

}  // namespace bimart
