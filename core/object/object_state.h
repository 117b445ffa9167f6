// Object states and posing (DESIGN §4): 7 numbers per frame [angle, rx, ry, rz, tx, ty, tz].
// The top part is first rotated by `angle` about -z (through the origin), then the whole
// object by the root axis-angle (rx, ry, rz) and translation (tx, ty, tz).
#pragma once

#include <algorithm>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/object/articulated_object.h"

namespace bimart {

struct ObjectState {
  double angle = 0;                                   // hinge angle (rad)
  Eigen::Vector3d root_rotation = Eigen::Vector3d::Zero();  // axis-angle (rad)
  Eigen::Vector3d root_translation = Eigen::Vector3d::Zero();  // metres

  // From 7 numbers in ARCTIC order; throws bimart::Error when one is not finite.
  static ObjectState from_row(const double* row);
  static ObjectState from_row(const float* row);
  Eigen::Matrix<double, 7, 1> to_row() const;
};

// Rotation by `angle` about -z through the origin: the top part's canonical pose.
Eigen::Isometry3d top_to_canonical(double angle);
// The root pose: canonical frame -> world frame.
Eigen::Isometry3d canonical_to_world(const ObjectState& state);

// Part vertices [V, 3] in the canonical frame (articulation applied, root pose not).
using PartVertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
struct PosedObject {
  PartVertices top;
  PartVertices bottom;
};
PosedObject pose_canonical(const ArticulatedObject& object, double angle);
// Both parts in the world frame.
PosedObject pose_world(const ArticulatedObject& object, const ObjectState& state);

// The object's meshes at a hinge angle in the canonical frame (faces unchanged).
TriangleMesh posed_top(const ArticulatedObject& object, double angle);

// Applies a rigid transform to every vertex.
PartVertices transform_vertices(const Eigen::Isometry3d& T, const PartVertices& v);

// s_o = (1 - 0.15) / max ||v|| over both parts in the canonical frame (paper eq. 1).
// Throws when every vertex sits at the origin.
double object_scale(const ArticulatedObject& object);

}  // namespace bimart
