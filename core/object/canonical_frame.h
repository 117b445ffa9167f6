// The canonical pose of a two-part object about its hinge (DESIGN §4; issue 38, "any
// canonical frame"): with the hinge already along −z through the origin, the turn about it
// that puts the top part above the bottom part (+y, from the bottom's surface centroid to
// the top's), as in every procedural family, and the shift along it that centres the
// object's extent on the origin. Every model sees objects in it: the pipeline's trajectory
// stages, the training data and `bimart object import` apply it (docs/objects.md); an object
// turned about its hinge any way gets the same canonical object back
// (tests/object/canonical_frame_test.cc).
#pragma once

#include <ATen/core/Tensor.h>
#include <Eigen/Geometry>

#include "core/geometry/triangle_mesh.h"
#include "core/object/articulated_object.h"

namespace bimart {

// Area-weighted centroid of the surface (independent of how finely it is meshed).
Eigen::Vector3d surface_centroid(const TriangleMesh& mesh);

// The rigid transform (a turn about z, then a shift along z) that takes parts whose hinge is
// −z through the origin to the canonical pose. When the parts' centroids lie on one line
// along the hinge (side by side along it), the whole object is turned towards −x instead;
// when its centroid is on the axis too, no turn. `extent`: the parts' size (m), for the
// tolerances.
Eigen::Isometry3d canonical_pose_about_hinge(const TriangleMesh& top, const TriangleMesh& bottom, double extent);

// An object moved to its canonical pose about the hinge: what every model sees, however the
// object arrived (a file, an ARCTIC folder, `object import`, a procedural family, a turned
// copy), so that the results do not depend on which way its parts point about the hinge.
struct CanonicalObject {
  ArticulatedObject object;
  Eigen::Isometry3d from_source = Eigen::Isometry3d::Identity();  // source frame -> canonical frame
  bool moved = false;  // false: canonical already (within 1e-9 rad and 1e-9 of its size); object unchanged
};
CanonicalObject to_canonical(const ArticulatedObject& object);

// Object states [N, 7] of the source object -> the states that put the canonical object
// exactly where they put the source (root pose T -> T * from_source^-1; the hinge angle is
// unchanged: from_source turns about the hinge and shifts along it). Same dtype.
at::Tensor canonical_states(const at::Tensor& states, const Eigen::Isometry3d& from_source);

}  // namespace bimart
