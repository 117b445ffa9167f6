#include "core/object/object_distance.h"

#include <algorithm>
#include <limits>

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

}  // namespace

ObjectDistance::ObjectDistance(const ArticulatedObject& object)
    : top_(object.top), bottom_(object.bottom) {}

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
