#include "core/geometry/euler.h"

#include <stdexcept>

#include <Eigen/Geometry>

namespace bimart {

bool is_euler_order(const std::string& order) {
  if (order.size() != 3) return false;
  for (std::size_t i = 0; i < 3; ++i) {
    if (order[i] != 'x' && order[i] != 'y' && order[i] != 'z') return false;
    if (i > 0 && order[i] == order[i - 1]) return false;
  }
  return true;
}

Eigen::Matrix3d euler_to_matrix(const std::string& order, const Eigen::Vector3d& angles) {
  if (!is_euler_order(order)) throw std::invalid_argument("unknown Euler order '" + order + "'");
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d axis = Eigen::Vector3d::Unit(order[i] - 'x');
    r = Eigen::AngleAxisd(angles[i], axis).toRotationMatrix() * r;  // fixed axes: later turns act on the left
  }
  return r;
}

}  // namespace bimart
