// Smooth interpolation of rotations through keys: a cubic spline in the tangent space of a
// reference rotation (the first key's). Each key R_i is written as R_ref · exp(v_i) with v_i
// an axis-angle vector, chosen among its equivalents (v + 2πk·axis) closest to v_{i-1}, so
// consecutive keys are joined the short way (less than half a turn apart) and a sequence of
// keys may turn more than once around. The three components of v(t) are cubic splines
// (core/trajectory/cubic_spline.h) and R(t) = R_ref · exp(v(t)): C² (exp is smooth), exactly
// the key rotations at the keys, and a unit quaternion at every time by construction.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/trajectory/cubic_spline.h"

namespace bimart {

class RotationSpline {
 public:
  // `times` strictly increasing, one rotation each (at least one).
  RotationSpline(const std::vector<double>& times, const std::vector<Eigen::Quaterniond>& rotations,
                 CubicSpline::End end);
  // Unit quaternion at time t (continued past the ends as CubicSpline does).
  Eigen::Quaterniond operator()(double t) const;

 private:
  Eigen::Quaterniond reference_;
  std::vector<CubicSpline> components_;  // x, y, z of the tangent vector
};

// Among the axis-angle vectors equivalent to `v` (the same rotation), the one closest to
// `previous`: keeps a per-frame axis-angle track continuous through half a turn.
Eigen::Vector3d unwrap_axis_angle(const Eigen::Vector3d& v, const Eigen::Vector3d& previous);

}  // namespace bimart
