// Closed, outward-oriented, subdivided primitive meshes for procedural objects. Each takes
// a target edge length `spacing` so that parts have enough vertices for BPS and contact
// maps. Written by hand rather than remeshed with CGAL: the lattice is exact, deterministic
// and cheap (CGAL's isotropic remeshing would add run time per object and compile time).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/geometry/triangle_mesh.h"

namespace bimart::shapes {

// The box [lo, hi] with edges and corners rounded by `radius` (0: sharp; clamped to just
// under half the smallest side).
TriangleMesh rounded_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double radius, double spacing);

// A cylinder around coordinate axis `axis` (0 = x, 1 = y, 2 = z) through `center`, of
// `length` along the axis, whose rims are rounded by `edge_radius` (0: a plain cylinder;
// radius: a capsule; clamped to min(radius, length / 2)).
TriangleMesh rounded_cylinder(const Eigen::Vector3d& center, int axis, double radius, double length,
                              double edge_radius, double spacing);

// A capsule: a cylinder with hemispherical ends, total `length` along `axis`.
TriangleMesh capsule(const Eigen::Vector3d& center, int axis, double radius, double length, double spacing);

// A torus around `axis` through `center`: ring radius `major`, tube radius `minor`.
TriangleMesh torus(const Eigen::Vector3d& center, int axis, double major, double minor, double spacing);

// Appends `m` to `to` as a separate component.
void append(TriangleMesh& to, const TriangleMesh& m);

// `m` with every vertex moved by `T`.
TriangleMesh transformed(const TriangleMesh& m, const Eigen::Isometry3d& T);

}  // namespace bimart::shapes
