#include "core/object/canonical_frame.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>

#include "core/geometry/rotation.h"
#include "core/object/mesh_repair.h"
#include "core/object/object_state.h"

namespace bimart {

Eigen::Vector3d surface_centroid(const TriangleMesh& m) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double area = 0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    const double w = 0.5 * (b - a).cross(c - a).norm();
    sum += w * (a + b + c) / 3;
    area += w;
  }
  return area > 0 ? Eigen::Vector3d(sum / area) : Eigen::Vector3d(m.vertices.colwise().mean());
}

Eigen::Isometry3d canonical_pose_about_hinge(const TriangleMesh& top, const TriangleMesh& bottom, double extent) {
  // About the axis: the top part above the bottom part (+y).
  const Eigen::Vector3d ct = surface_centroid(top), cb = surface_centroid(bottom);
  const Eigen::Vector2d up = (ct - cb).head<2>();
  Eigen::Isometry3d roll = Eigen::Isometry3d::Identity();
  if (up.norm() > 1e-3 * extent) {
    roll.linear() = rotation_about(Eigen::Vector3d::UnitZ(), M_PI / 2 - std::atan2(up.y(), up.x()));
  } else {
    // Top and bottom side by side along the axis: put the whole object towards -x instead.
    const Eigen::Vector2d c = (0.5 * (ct + cb)).head<2>();
    if (c.norm() > 1e-3 * extent) roll.linear() = rotation_about(Eigen::Vector3d::UnitZ(), M_PI - std::atan2(c.y(), c.x()));
  }
  // Along the axis: the extent along z centred on the origin (a turn about z keeps z).
  const double zlo = std::min(top.vertices.col(2).minCoeff(), bottom.vertices.col(2).minCoeff());
  const double zhi = std::max(top.vertices.col(2).maxCoeff(), bottom.vertices.col(2).maxCoeff());
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation() = Eigen::Vector3d(0, 0, -0.5 * (zlo + zhi));
  return shift * roll;
}

CanonicalObject to_canonical(const ArticulatedObject& object) {
  CanonicalObject c;
  c.object = object;
  const double extent = std::max({bounding_radius(object.top), bounding_radius(object.bottom), 1e-12});
  const Eigen::Isometry3d pose = canonical_pose_about_hinge(object.top, object.bottom, extent);
  const double angle = Eigen::AngleAxisd(pose.linear()).angle();
  if (angle < 1e-9 && pose.translation().norm() < 1e-9 * extent) return c;
  c.from_source = pose;
  c.moved = true;
  for (TriangleMesh* m : {&c.object.top, &c.object.bottom}) m->vertices = transform_vertices(pose, m->vertices);
  return c;
}

at::Tensor canonical_states(const at::Tensor& states, const Eigen::Isometry3d& from_source) {
  at::Tensor out = states.to(at::kCPU, at::kDouble).contiguous().clone();
  double* rows = out.data_ptr<double>();
  const Eigen::Isometry3d back = from_source.inverse();
  for (std::int64_t t = 0; t < out.size(0); ++t) {
    ObjectState s = ObjectState::from_row(rows + 7 * t);
    const Eigen::Isometry3d U = canonical_to_world(s) * back;
    s.root_rotation = matrix_to_axis_angle(U.linear());
    s.root_translation = U.translation();
    Eigen::Map<Eigen::Matrix<double, 7, 1>>(rows + 7 * t) = s.to_row();
  }
  return out.to(states.scalar_type());
}

}  // namespace bimart
