#include "core/geometry/point_guard.h"

#include <fmt/format.h>

#include <cmath>

#include "core/util/error.h"

namespace bimart {

void check_point(const Eigen::Vector3d& p, const char* what, Eigen::Index row) {
  const bool finite = p.allFinite();
  if (finite && p.cwiseAbs().maxCoeff() <= kMaxCoordinate) return;
  const std::string which = row >= 0 ? fmt::format("point {}", row) : std::string("point");
  throw Error(fmt::format("{}: {} is ({:.6g}, {:.6g}, {:.6g}): {}", what, which, p.x(), p.y(), p.z(),
                          finite ? fmt::format("more than {:g} m from the origin", kMaxCoordinate)
                                 : std::string("not finite")));
}

void check_points(const Points3& points, const char* what) {
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const auto r = points.row(i);
    if (!(std::abs(r(0)) <= kMaxCoordinate && std::abs(r(1)) <= kMaxCoordinate && std::abs(r(2)) <= kMaxCoordinate))
      check_point(r.transpose(), what, i);
  }
}

template <class T>
long first_bad(const T* v, long n, double bound) {
  for (long i = 0; i < n; ++i)
    if (!(std::abs(static_cast<double>(v[i])) <= bound)) return i;  // NaN fails the test too
  return -1;
}

long first_out_of_bounds(const double* values, long n, double bound) { return first_bad(values, n, bound); }
long first_out_of_bounds(const float* values, long n, double bound) { return first_bad(values, n, bound); }

}  // namespace bimart
