// Bounds on the numbers the geometry core accepts (docs/reliability.md). Every entry to
// CGAL, nanoflann and Ceres checks its points with these, so a NaN or an absurd value ends
// in a bimart::Error naming the point, never in a crash inside a library (CGAL hands a NaN
// to GMP, which raises SIGFPE).
#pragma once

#include <string>

#include <Eigen/Core>

#include "core/geometry/triangle_mesh.h"

namespace bimart {

// Coordinates of query points, in metres in the frame they are queried in: a hand 10 km
// from its object is no scene, and squared distances keep full precision well past it.
constexpr double kMaxCoordinate = 1e4;
// Rotations (rad), translations (m), hinge angles (rad) and shape coefficients of poses:
// each component at most this in magnitude. Posing bounded inputs gives bounded points.
constexpr double kMaxPoseValue = 1e3;

// Throws bimart::Error "<what>: point <row> is (x, y, z): not finite" or "... more than
// 10000 m from the origin" (row left out when negative).
void check_point(const Eigen::Vector3d& p, const char* what, Eigen::Index row = -1);
// Every row of an [M, 3] matrix.
void check_points(const Points3& points, const char* what);
// The first component of `values[0..n)` that is not finite or beyond `bound`, or -1.
long first_out_of_bounds(const double* values, long n, double bound);
long first_out_of_bounds(const float* values, long n, double bound);

}  // namespace bimart
