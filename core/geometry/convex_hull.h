// The convex hull of a point set as a closed triangle mesh (CGAL's convex_hull_3), with
// outward faces: what a hollow part would be if it were full, for cavity tests
// (core/object/object_distance.h, max_cavity_depth).
#pragma once

#include "core/geometry/triangle_mesh.h"

namespace bimart {

// Throws bimart::Error for fewer than 4 points or points that span no volume.
TriangleMesh convex_hull(const Points3& points);

}  // namespace bimart
