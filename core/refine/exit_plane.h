// Where a hand sunk into a thin part leaves it (the refinement's exit planes,
// RefineOptions::pen_exit_depth; docs/refinement.md): towards the rest of the hand, not
// each inside vertex to its nearest surface — in a part thinner than twice their depth the
// nearest side flips between vertices and rounds, and the hand stays stuck in it.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/geometry/point_guard.h"
#include "core/object/object_distance.h"

namespace bimart {

// A tangent plane of the object surface: a point on it and its unit outward normal.
struct Plane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

// The unit direction from a frame's inside vertices (signed distance > 0 in `near`, indices
// into v) to the mean of the rest of the hand; zero when the hand is wholly inside or not
// inside at all.
Eigen::Vector3d exit_direction(const Points3& v, const std::vector<std::pair<int, ObjectSurfaceQuery>>& near);

// The plane where a ray from inside point p along unit e leaves the object, its normal
// turned to face along e; none when the ray is still inside after kExitReach (a ray along a
// thin part's plane can run inside it for its whole length: a plane where the ray gave up
// pushed hands 6 cm off a laptop's lid).
constexpr double kExitReach = 0.06;  // m
std::optional<Plane> exit_plane(const ObjectDistance& dist, const ObjectState& state, Eigen::Vector3d p,
                                const Eigen::Vector3d& e);

}  // namespace bimart
