// Typed values of the trajectory YAML files (numbers, 3-vectors, strings, rotations in
// degrees), each error naming the file, line and field. Shared by the trajectory reader
// (yaml_trajectory.cc) and the `hands:` block (core/directing/hand_constraints.cc).
#pragma once

#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/util/error.h"

namespace YAML {
class Node;
}

namespace bimart {

struct YamlReader {
  std::string file;

  SourceLocation at(const YAML::Node& n) const;
  // A finite number.
  double number(const YAML::Node& n, const std::string& field) const;
  // A whole number in [lo, hi].
  std::int64_t whole(const YAML::Node& n, const std::string& field, std::int64_t lo, std::int64_t hi) const;
  Eigen::Vector3d vec3(const YAML::Node& n, const std::string& field) const;
  std::string text(const YAML::Node& n, const std::string& field) const;
  // `{euler_ORDER: [a, b, c]}` or `{axis_angle: [x, y, z]}`, degrees (docs/trajectories.md).
  Eigen::Quaterniond rotation(const YAML::Node& n) const;
};

}  // namespace bimart
