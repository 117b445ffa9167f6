#include "core/object/object_distance.h"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include "core/geometry/convex_hull.h"

namespace bimart {
namespace {

// World -> part frame for each part at `state` (the top part's own frame is its pose at angle 0).
struct PartFrames {
  Eigen::Isometry3d world_to_bottom;
  Eigen::Isometry3d world_to_top;
};

PartFrames part_frames(const ObjectState& state) {
  PartFrames f;
  f.world_to_bottom = canonical_to_world(state).inverse();
  f.world_to_top = top_to_canonical(state.angle).inverse() * f.world_to_bottom;
  return f;
}

Eigen::Matrix<double, Eigen::Dynamic, 4> hull_planes(const TriangleMesh& part) {
  const TriangleMesh hull = convex_hull(part.vertices);
  std::vector<std::pair<double, Eigen::Vector4d>> faces;  // area, plane
  for (Eigen::Index f = 0; f < hull.num_faces(); ++f) {
    const Eigen::Vector3d a = hull.vertices.row(hull.faces(f, 0)), b = hull.vertices.row(hull.faces(f, 1)),
                          c = hull.vertices.row(hull.faces(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0)) continue;
    const Eigen::Vector3d u = n.normalized();
    // A sliver of a flat facet (three nearly collinear points) gets its normal from rounding
    // and would cut into the hull; only supporting planes are kept: no hull vertex beyond
    // the plane by more than 0.1 µm. The facet's other triangles give its plane.
    if ((hull.vertices * u).maxCoeff() - u.dot(a) > 1e-7) continue;
    faces.push_back({n.norm(), Eigen::Vector4d(u.x(), u.y(), u.z(), u.dot(a))});
  }
  // Largest faces first: a point outside is usually rejected by one of the first planes.
  std::sort(faces.begin(), faces.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  Eigen::Matrix<double, Eigen::Dynamic, 4> planes(static_cast<Eigen::Index>(faces.size()), 4);
  for (size_t f = 0; f < faces.size(); ++f) planes.row(static_cast<Eigen::Index>(f)) = faces[f].second.transpose();
  return planes;
}

// How far p lies inside the convex polytope (m), or any value ≤ `stop` once it is known to
// be no more than `stop` (≤ 0: outside).
double depth_inside(const Eigen::Matrix<double, Eigen::Dynamic, 4>& planes, const Eigen::Vector3d& p, double stop) {
  double depth = std::numeric_limits<double>::infinity();
  for (Eigen::Index f = 0; f < planes.rows(); ++f) {
    depth = std::min(depth, planes(f, 3) - planes(f, 0) * p.x() - planes(f, 1) * p.y() - planes(f, 2) * p.z());
    if (depth <= stop) break;
  }
  return depth;
}

}  // namespace

ObjectDistance::ObjectDistance(const ArticulatedObject& object)
    : top_(object.top), bottom_(object.bottom), top_hull_(hull_planes(object.top)),
      bottom_hull_(hull_planes(object.bottom)) {}

double ObjectDistance::cavity_depth(const ObjectState& state, const Eigen::Vector3d& p, double stop) const {
  const PartFrames f = part_frames(state);
  const Eigen::Vector3d p_top = f.world_to_top * p, p_bottom = f.world_to_bottom * p;
  const double inside_hull = std::max(depth_inside(top_hull_, p_top, stop), depth_inside(bottom_hull_, p_bottom, stop));
  if (inside_hull <= stop) return 0.0;
  const double sd = std::max(top_.signed_distance(p_top), bottom_.signed_distance(p_bottom));
  if (sd >= 0) return 0.0;  // inside the object: penetration, not a cavity
  return std::min(inside_hull, -sd);
}

double ObjectDistance::max_cavity_depth(const ObjectState& state, const Points3& points_world, double floor) const {
  double best = std::max(floor, 0.0);
  for (Eigen::Index i = 0; i < points_world.rows(); ++i)
    best = std::max(best, cavity_depth(state, points_world.row(i).transpose(), best));
  return best > floor ? best : 0.0;
}

std::vector<int> ObjectDistance::cavity_points(const ObjectState& state, const Points3& points_world,
                                               double floor) const {
  std::vector<int> out;
  for (Eigen::Index i = 0; i < points_world.rows(); ++i)
    if (cavity_depth(state, points_world.row(i).transpose(), std::max(floor, 0.0)) > floor)
      out.push_back(static_cast<int>(i));
  return out;
}

ObjectSurfaceQuery ObjectDistance::query(const ObjectState& state, const Eigen::Vector3d& p_world,
                                         ObjectPart part) const {
  const PartFrames f = part_frames(state);
  const Eigen::Isometry3d canonical_to_w = canonical_to_world(state);
  ObjectSurfaceQuery out;
  auto from_top = [&]() {
    const SurfaceQuery q = top_.query(f.world_to_top * p_world);
    const Eigen::Isometry3d top_to_w = canonical_to_w * top_to_canonical(state.angle);
    return ObjectSurfaceQuery{q.signed_distance, top_to_w * q.closest, ObjectPart::Top,
                              top_to_w.linear() * q.normal};
  };
  auto from_bottom = [&]() {
    const SurfaceQuery q = bottom_.query(f.world_to_bottom * p_world);
    return ObjectSurfaceQuery{q.signed_distance, canonical_to_w * q.closest, ObjectPart::Bottom,
                              canonical_to_w.linear() * q.normal};
  };
  if (part == ObjectPart::Top) return from_top();
  if (part == ObjectPart::Bottom) return from_bottom();
  // Union of the parts: the larger signed distance (the nearer surface when outside both).
  const ObjectSurfaceQuery t = from_top();
  const ObjectSurfaceQuery b = from_bottom();
  return t.signed_distance > b.signed_distance ? t : b;
}

Eigen::VectorXd ObjectDistance::signed_distances(const ObjectState& state,
                                                 const Points3& points_world,
                                                 ObjectPart part) const {
  const PartFrames f = part_frames(state);
  Eigen::VectorXd out(points_world.rows());
  for (Eigen::Index i = 0; i < points_world.rows(); ++i) {
    const Eigen::Vector3d p = points_world.row(i).transpose();
    if (part == ObjectPart::Top) {
      out(i) = top_.signed_distance(f.world_to_top * p);
    } else if (part == ObjectPart::Bottom) {
      out(i) = bottom_.signed_distance(f.world_to_bottom * p);
    } else {
      out(i) = std::max(top_.signed_distance(f.world_to_top * p),
                        bottom_.signed_distance(f.world_to_bottom * p));
    }
  }
  return out;
}

std::vector<std::pair<int, ObjectSurfaceQuery>> ObjectDistance::near_surface(
    const ObjectState& state, const Points3& points_world, double margin) const {
  const PartFrames f = part_frames(state);
  const Eigen::AlignedBox3d top_box = top_.bounding_box(), bottom_box = bottom_.bounding_box();
  std::vector<std::pair<int, ObjectSurfaceQuery>> out;
  for (Eigen::Index i = 0; i < points_world.rows(); ++i) {
    const Eigen::Vector3d p = points_world.row(i).transpose();
    const bool near_top = top_box.exteriorDistance(f.world_to_top * p) <= margin;
    const bool near_bottom = bottom_box.exteriorDistance(f.world_to_bottom * p) <= margin;
    if (!near_top && !near_bottom) continue;
    const ObjectPart part = near_top && near_bottom ? ObjectPart::Whole
                                                    : (near_top ? ObjectPart::Top : ObjectPart::Bottom);
    const ObjectSurfaceQuery q = query(state, p, part);
    if (q.signed_distance > -margin) out.emplace_back(static_cast<int>(i), q);
  }
  return out;
}

double ObjectDistance::max_signed_distance(const ObjectState& state, const Points3& points_world,
                                           ObjectPart part) const {
  const PartFrames f = part_frames(state);
  auto local = [&](const Eigen::Isometry3d& T) {
    Points3 out = (points_world * T.linear().transpose()).rowwise() + T.translation().transpose();
    return out;
  };
  double best = -std::numeric_limits<double>::infinity();
  if (part != ObjectPart::Bottom) best = std::max(best, top_.max_signed_distance(local(f.world_to_top)));
  if (part != ObjectPart::Top) best = std::max(best, bottom_.max_signed_distance(local(f.world_to_bottom)));
  return best;
}

}  // namespace bimart
