// Rotations: axis-angle vectors (direction = axis, length = angle in radians) and 3x3
// matrices, robust near angle 0 and near pi. Every part of bimart converts through here.
#pragma once

#include <Eigen/Core>

namespace bimart {

// Rodrigues' formula; exact identity for a zero vector, Taylor terms for tiny angles.
Eigen::Matrix3d axis_angle_to_matrix(const Eigen::Vector3d& axis_angle);

// The inverse: an angle in [0, pi]. At exactly pi the sign of the axis is arbitrary
// (both give the same matrix). The input is assumed to be a rotation (orthonormal, det +1).
Eigen::Vector3d matrix_to_axis_angle(const Eigen::Matrix3d& rotation);

// Rotation by `angle` (radians, right-handed) about `axis` (any non-zero length).
Eigen::Matrix3d rotation_about(const Eigen::Vector3d& axis, double angle);

// The smallest rotation taking direction `from` to direction `to` (both non-zero). For
// opposite directions it turns by pi about an axis perpendicular to `from`.
Eigen::Matrix3d rotation_between(const Eigen::Vector3d& from, const Eigen::Vector3d& to);

}  // namespace bimart
