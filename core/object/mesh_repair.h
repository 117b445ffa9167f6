// Reading part meshes from files, checking them, and closing open parts. Everything here
// that needs CGAL lives in mesh_repair.cc, so only that file pays CGAL's compile time.
#pragma once

#include <string>

#include "core/geometry/triangle_mesh.h"

namespace bimart {

// Reads OBJ, PLY, OFF or STL (by extension) with CGAL's polygon-soup reader. Polygons with
// more than three corners are split as fans (files store convex quads in practice).
// Throws bimart::Error naming the file when it is missing or unreadable.
TriangleMesh read_mesh_file(const std::string& path);

// Throws bimart::Error naming `file` when the mesh is empty, has a non-finite coordinate,
// a face index out of range, or a face of zero area (relative to the mesh's size).
void validate_mesh(const TriangleMesh& mesh, const std::string& file);

// Half the diagonal of the axis-aligned bounding box (metres).
double bounding_radius(const TriangleMesh& mesh);

// What close_and_orient changed.
struct RepairReport {
  int holes_filled = 0;
  int faces_added = 0;
  int vertices_added = 0;
  bool reoriented = false;  // faces were flipped so that normals point outwards
  bool changed() const { return holes_filled > 0 || reoriented || vertices_added > 0; }
  std::string str() const;  // e.g. "filled 2 holes (+34 faces, +5 vertices)"
};

// Fills every hole (each boundary cycle, with CGAL's triangulate_and_refine_hole: a patch
// refined to the density of its surroundings, so contact maps find vertices on it) and
// orients each closed component outwards. Parts of real objects are often open where one
// mesh was cut into two; such cuts are flat, so the patch is not faired (fairing bulged a
// flat cut by ~18% of a box's volume). Throws bimart::Error naming `file` when the mesh
// cannot be closed.
RepairReport close_and_orient(TriangleMesh& mesh, const std::string& file);

// True when the mesh is a valid, combinatorially closed 2-manifold (CGAL::is_closed).
// Disjoint closed components are fine.
bool is_closed_mesh(const TriangleMesh& mesh);

// Signed volume by the divergence theorem: positive when faces are oriented outwards.
double signed_volume(const TriangleMesh& mesh);

}  // namespace bimart
