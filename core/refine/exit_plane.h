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

// The unit direction from a frame's trapped vertices (rows of v: inside the object, or in a
// hollow part's cavity) to the mean of the rest of the hand; zero when the hand is wholly
// trapped or not at all.
Eigen::Vector3d exit_direction(const Points3& v, const std::vector<int>& trapped);

// The plane where a ray from inside point p along unit e leaves the object, its normal
// turned to face along e; none when the ray is still inside after kExitReach (a ray along a
// thin part's plane can run inside it for its whole length: a plane where the ray gave up
// pushed hands 6 cm off a laptop's lid).
constexpr double kExitReach = 0.06;  // m
std::optional<Plane> exit_plane(const ObjectDistance& dist, const ObjectState& state, Eigen::Vector3d p,
                                const Eigen::Vector3d& e);

// From a point outside the object (in a hollow part's cavity) along unit e: the plane where
// the ray leaves the object after passing through it (a box's wall between a finger inside
// the box and the rest of the hand outside); none when the ray meets no surface within
// kExitReach (the way towards the hand is open: a hand reaching in through the opening) or
// does not leave it within kExitReach after that.
std::optional<Plane> exit_plane_through(const ObjectDistance& dist, const ObjectState& state, Eigen::Vector3d p,
                                        const Eigen::Vector3d& e);

}  // namespace bimart
