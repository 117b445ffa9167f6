#include "core/trajectory/yaml_reader.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "core/geometry/euler.h"
#include "core/geometry/rotation.h"
#include "core/util/yaml_keys.h"

namespace bimart {

SourceLocation YamlReader::at(const YAML::Node& n) const { return yaml_location(file, n); }

double YamlReader::number(const YAML::Node& n, const std::string& field) const {
  if (!n.IsScalar()) throw Error(at(n), field + " must be a number");
  double v = 0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    throw Error(at(n), field + " must be a number, got '" + n.Scalar() + "'");
  }
  if (!std::isfinite(v)) throw Error(at(n), field + " is not a finite number ('" + n.Scalar() + "')");
  return v;
}

std::int64_t YamlReader::whole(const YAML::Node& n, const std::string& field, std::int64_t lo, std::int64_t hi) const {
  const double v = number(n, field);
  if (v != std::floor(v) || v < static_cast<double>(lo) || v > static_cast<double>(hi))
    throw Error(at(n), fmt::format("{} must be a whole number in [{}, {}], got {}", field, lo, hi, n.Scalar()));
  return static_cast<std::int64_t>(v);
}

Eigen::Vector3d YamlReader::vec3(const YAML::Node& n, const std::string& field) const {
  if (!n.IsSequence() || n.size() != 3) throw Error(at(n), field + " must be a list of 3 numbers");
  return {number(n[0], field), number(n[1], field), number(n[2], field)};
}

std::string YamlReader::text(const YAML::Node& n, const std::string& field) const {
  if (!n.IsScalar()) throw Error(at(n), field + " must be a string");
  return n.Scalar();
}

Eigen::Quaterniond YamlReader::rotation(const YAML::Node& n) const {
  constexpr double kDeg = M_PI / 180.0;
  if (!n.IsMap() || n.size() != 1)
    throw Error(at(n), "rotation must be a map with one key: euler_xyz (or another order, e.g. euler_zyx) or "
                       "axis_angle, each with 3 numbers in degrees");
  const auto kv = *n.begin();
  const std::string key = kv.first.Scalar();
  const Eigen::Vector3d v = vec3(kv.second, "rotation." + key) * kDeg;
  if (key == "axis_angle") return Eigen::Quaterniond(axis_angle_to_matrix(v));
  if (key.rfind("euler_", 0) == 0 && is_euler_order(key.substr(6)))
    return Eigen::Quaterniond(euler_to_matrix(key.substr(6), v));
  throw Error(at(kv.first), "unknown rotation '" + key +
                                "': use axis_angle, or euler_ with an order such as xyz, zyx, zxz (docs/trajectories.md)");
}

}  // namespace bimart
