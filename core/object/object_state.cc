#include "core/object/object_state.h"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "core/geometry/point_guard.h"
#include "core/geometry/rotation.h"
#include "core/util/error.h"

namespace bimart {

namespace {

template <typename T>
ObjectState state_from(const T* row) {
  static const char* names[7] = {"angle", "rx", "ry", "rz", "tx", "ty", "tz"};
  for (int i = 0; i < 7; ++i)
    if (!std::isfinite(static_cast<double>(row[i])))
      throw Error(std::string("object state: ") + names[i] + " is not finite");
    else if (std::abs(static_cast<double>(row[i])) > kMaxPoseValue)
      throw Error(fmt::format("object state: {} = {:g} is beyond the bound ±{:g} (rad or m)", names[i],
                              static_cast<double>(row[i]), kMaxPoseValue));
  ObjectState s;
  s.angle = row[0];
  s.root_rotation = Eigen::Vector3d(row[1], row[2], row[3]);
  s.root_translation = Eigen::Vector3d(row[4], row[5], row[6]);
  return s;
}

}  // namespace

ObjectState ObjectState::from_row(const double* row) { return state_from(row); }
ObjectState ObjectState::from_row(const float* row) { return state_from(row); }

Eigen::Matrix<double, 7, 1> ObjectState::to_row() const {
  Eigen::Matrix<double, 7, 1> r;
  r << angle, root_rotation, root_translation;
  return r;
}

Eigen::Isometry3d top_to_canonical(double angle) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation_about(Eigen::Vector3d(0, 0, -1), angle);
  return T;
}

Eigen::Isometry3d canonical_to_world(const ObjectState& state) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = axis_angle_to_matrix(state.root_rotation);
  T.translation() = state.root_translation;
  return T;
}

PartVertices transform_vertices(const Eigen::Isometry3d& T, const PartVertices& v) {
  PartVertices out = v * T.linear().transpose();
  out.rowwise() += T.translation().transpose();
  return out;
}

PosedObject pose_canonical(const ArticulatedObject& object, double angle) {
  return {transform_vertices(top_to_canonical(angle), object.top.vertices), object.bottom.vertices};
}

PosedObject pose_world(const ArticulatedObject& object, const ObjectState& state) {
  const Eigen::Isometry3d root = canonical_to_world(state);
  return {transform_vertices(root * top_to_canonical(state.angle), object.top.vertices),
          transform_vertices(root, object.bottom.vertices)};
}

TriangleMesh posed_top(const ArticulatedObject& object, double angle) {
  TriangleMesh m = object.top;
  m.vertices = transform_vertices(top_to_canonical(angle), object.top.vertices);
  return m;
}

double object_scale(const ArticulatedObject& object) {
  double r = 0;
  for (const TriangleMesh* m : {&object.top, &object.bottom})
    if (m->num_vertices() > 0) r = std::max(r, m->vertices.rowwise().norm().maxCoeff());
  if (!(r > 0)) throw Error("object '" + object.name + "' has no vertices away from the origin");
  return (1.0 - 0.15) / r;
}

}  // namespace bimart
