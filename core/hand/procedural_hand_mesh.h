// Meshing a smooth implicit surface into a closed triangle mesh of a given vertex count,
// and checking such a mesh, with CGAL's simplification and mesh processing (the only translation unit of the procedural hand
// that includes CGAL, which is slow to compile).
#pragma once

#include <functional>

#include <Eigen/Core>

#include "core/geometry/triangle_mesh.h"

namespace bimart {

struct ImplicitMeshOptions {
  int target_vertices = 800;
  double grid_step = 0.0015;  // metres: grid of the dense first mesh
  int relax_iterations = 3;   // tangential relaxation + projection after simplifying
};

// `sdf` is a signed distance (negative inside, about metre-scaled) whose surface lies inside
// the box [lo, hi]. Meshes densely by marching tetrahedra, simplifies by Lindstrom-Turk edge
// collapse (CGAL) to the target vertex count (curvature-adaptive: fine on fingers, coarse on
// the palm), relaxes tangentially and projects the vertices back onto the surface. The
// result is closed, outward oriented and free of self-intersections, or bimart::Error is
// thrown. Deterministic: the same inputs give the same mesh, vertex order included.
TriangleMesh mesh_implicit_surface(const std::function<double(const Eigen::Vector3d&)>& sdf,
                                   const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                   const ImplicitMeshOptions& options = {});

struct SurfaceCheck {
  bool manifold = false;           // every face could be added to a halfedge mesh
  bool closed = false;             // no border edges
  bool self_intersecting = true;   // some pair of non-adjacent faces intersects
  bool outward = false;            // bounded volume with outward normals
};

// CGAL's Polygon_mesh_processing verdicts on a triangle mesh.
SurfaceCheck check_surface(const TriangleMesh& mesh);

}  // namespace bimart
