// The canonical pose of a two-part object about its hinge (DESIGN §4; issue 38, "any
// canonical frame"): with the hinge already along −z through the origin, the turn about it
// that puts the top part above the bottom part (+y, from the bottom's surface centroid to
// the top's), as in every procedural family, and the shift along it that centres the
// object's extent on the origin. `bimart object import` applies it; an object turned about
// its hinge any way gets the same canonical object back (tests/object/canonical_frame_test.cc).
#pragma once

#include <Eigen/Geometry>

#include "core/geometry/triangle_mesh.h"

namespace bimart {

// Area-weighted centroid of the surface (independent of how finely it is meshed).
Eigen::Vector3d surface_centroid(const TriangleMesh& mesh);

// The rigid transform (a turn about z, then a shift along z) that takes parts whose hinge is
// −z through the origin to the canonical pose. When the parts' centroids lie on one line
// along the hinge (side by side along it), the whole object is turned towards −x instead;
// when its centroid is on the axis too, no turn. `extent`: the parts' size (m), for the
// tolerances.
Eigen::Isometry3d canonical_pose_about_hinge(const TriangleMesh& top, const TriangleMesh& bottom, double extent);

}  // namespace bimart
