// Signed distance from world-space points to a posed articulated object (DESIGN §6): one
// MeshDistance per part, built once in the part's own frame; each query moves the points
// into the part's frame with the object state (parts are rigid). Positive inside.
// The whole object is the union of both parts: sd = max(sd_top, sd_bottom).
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/geometry/mesh_distance.h"
#include "core/object/articulated_object.h"
#include "core/object/object_state.h"

namespace bimart {

enum class ObjectPart { Top = 0, Bottom = 1, Whole = 2 };

struct ObjectSurfaceQuery {
  double signed_distance = 0;                         // metres; > 0 inside
  Eigen::Vector3d closest = Eigen::Vector3d::Zero();  // nearest surface point, world frame
  ObjectPart part = ObjectPart::Bottom;               // the part the nearest point lies on
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();   // unit outward normal there, world frame
};

class ObjectDistance {
 public:
  explicit ObjectDistance(const ArticulatedObject& object);

  // One world-space point at one object state.
  ObjectSurfaceQuery query(const ObjectState& state, const Eigen::Vector3d& p_world,
                           ObjectPart part = ObjectPart::Whole) const;
  // Row-wise signed distances of [M, 3] world points at one state.
  Eigen::VectorXd signed_distances(const ObjectState& state, const Points3& points_world,
                                   ObjectPart part = ObjectPart::Whole) const;

  // max over the rows of signed_distances(state, points_world, part), with pruning
  // (MeshDistance::max_signed_distance): the deepest point, as Pen, Con and Art need.
  double max_signed_distance(const ObjectState& state, const Points3& points_world,
                             ObjectPart part = ObjectPart::Whole) const;

  // The points (rows) inside the object or within `margin` (m) of its surface, with their
  // queries (the part with the larger signed distance); the rest are skipped after a
  // bounding-box test per part, which makes this cheap for a hand beside an object.
  std::vector<std::pair<int, ObjectSurfaceQuery>> near_surface(const ObjectState& state,
                                                               const Points3& points_world,
                                                               double margin) const;

  // How deep the deepest of the points lies in a cavity (m; 0 when none does): outside the
  // object, inside a part's convex hull, by the smaller of the two distances. A hand inside
  // a hollow part (a box's inside, the space between scissor blades) is outside the object,
  // so the signed distance calls it free; its hull does not (issue 38, "hollow parts").
  // Depths up to `floor` read 0: points less deep than it inside a hull are not queried
  // against the object (most of a hand touching a rounded part is just inside its hull).
  double max_cavity_depth(const ObjectState& state, const Points3& points_world, double floor = 0) const;
  // One point's cavity depth (as max_cavity_depth), or 0 (also when it is no more than
  // `stop`: then the object is not queried).
  double cavity_depth(const ObjectState& state, const Eigen::Vector3d& p, double stop = 0) const;
  // The points (rows) in a cavity deeper than `floor` (as max_cavity_depth measures it).
  std::vector<int> cavity_points(const ObjectState& state, const Points3& points_world, double floor) const;

  const MeshDistance& top() const { return top_; }
  const MeshDistance& bottom() const { return bottom_; }

 private:
  MeshDistance top_;
  MeshDistance bottom_;
  // Each part's convex hull (core/geometry/convex_hull.h) as its face planes [F, 4]: outward
  // unit normal n and offset c, n·p ≤ c inside. Inside a convex polytope the distance to its
  // surface is the smallest c − n·p, so no tree is needed.
  Eigen::Matrix<double, Eigen::Dynamic, 4> top_hull_, bottom_hull_;
};

}  // namespace bimart
