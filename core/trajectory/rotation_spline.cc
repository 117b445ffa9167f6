#include "core/trajectory/rotation_spline.h"

#include <cmath>
#include <stdexcept>

#include "core/geometry/rotation.h"

namespace bimart {

Eigen::Vector3d unwrap_axis_angle(const Eigen::Vector3d& v, const Eigen::Vector3d& previous) {
  const double angle = v.norm();
  Eigen::Vector3d axis;
  if (angle > 1e-12) {
    axis = v / angle;
  } else if (previous.norm() > 1e-12) {
    axis = previous.normalized();  // the identity is also 2πk about any axis
  } else {
    return v;
  }
  const double k = std::round((previous.dot(axis) - angle) / (2 * M_PI));
  return (angle + 2 * M_PI * k) * axis;
}

RotationSpline::RotationSpline(const std::vector<double>& times, const std::vector<Eigen::Quaterniond>& rotations,
                               CubicSpline::End end) {
  if (times.empty() || times.size() != rotations.size())
    throw std::invalid_argument("RotationSpline: one rotation per time, at least one");
  reference_ = rotations.front().normalized();
  std::vector<std::vector<double>> c(3, std::vector<double>(times.size()));
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < times.size(); ++i) {
    const Eigen::Matrix3d relative = (reference_.conjugate() * rotations[i].normalized()).toRotationMatrix();
    previous = unwrap_axis_angle(matrix_to_axis_angle(relative), previous);
    for (int k = 0; k < 3; ++k) c[k][i] = previous[k];
  }
  for (int k = 0; k < 3; ++k) components_.emplace_back(times, c[k], end);
}

Eigen::Quaterniond RotationSpline::operator()(double t) const {
  const Eigen::Vector3d v(components_[0](t), components_[1](t), components_[2](t));
  return (reference_ * Eigen::Quaterniond(axis_angle_to_matrix(v))).normalized();
}

}  // namespace bimart
