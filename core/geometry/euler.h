// Euler angles to rotation matrices, for rotations people write by hand (keyframes).
#pragma once

#include <string>

#include <Eigen/Core>

namespace bimart {

// Euler angles (radians) in the order `order`, three of x, y, z with no letter twice in a
// row ("xyz", "zyx", "zxz", ...), about the fixed (world) axes: "xyz" turns by a about x,
// then by b about y, then by c about z, R = Rz(c) Ry(b) Rx(a) (Blender's "XYZ Euler",
// SciPy's lower-case "xyz"). Throws std::invalid_argument for another order.
Eigen::Matrix3d euler_to_matrix(const std::string& order, const Eigen::Vector3d& angles);
bool is_euler_order(const std::string& order);

}  // namespace bimart
