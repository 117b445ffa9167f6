#include "core/refine/exit_plane.h"

#include <algorithm>
#include <cmath>

namespace bimart {

Eigen::Vector3d exit_direction(const Points3& v, const std::vector<int>& trapped) {
  Eigen::Vector3d sum_in = Eigen::Vector3d::Zero();
  int n_in = 0;
  for (int i : trapped) sum_in += v.row(i).transpose(), ++n_in;
  const int n_out = static_cast<int>(v.rows()) - n_in;
  if (n_in == 0 || n_out == 0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d sum_out = v.colwise().sum().transpose() - sum_in;  // the rest of the hand
  const Eigen::Vector3d e = sum_out / n_out - sum_in / n_in;
  return e.norm() > 1e-9 ? Eigen::Vector3d(e.normalized()) : Eigen::Vector3d::Zero();
}

namespace {
constexpr double kClose = 2e-4;  // m
}  // namespace

// Sphere tracing: a step of the signed distance never crosses the surface.
std::optional<Plane> exit_plane(const ObjectDistance& dist, const ObjectState& state, Eigen::Vector3d p,
                                const Eigen::Vector3d& e) {
  double travelled = 0;
  for (int step = 0; step < 32 && travelled < kExitReach; ++step) {
    const ObjectSurfaceQuery q = dist.query(state, p);
    // At a face that lets the ray out; or out already, past a face it grazed. (A face facing
    // the other way is where the ray started, near the side it must not leave by.)
    if (q.signed_distance < kClose && q.normal.dot(e) > 0) return Plane{q.closest, q.normal};
    if (q.signed_distance < -kClose) return Plane{q.closest, e};
    const double stride = std::max(q.signed_distance, kClose);
    p += stride * e;
    travelled += stride;
  }
  return std::nullopt;
}

std::optional<Plane> exit_plane_through(const ObjectDistance& dist, const ObjectState& state, Eigen::Vector3d p,
                                        const Eigen::Vector3d& e) {
  double travelled = 0;
  bool entered = false;
  for (int step = 0; step < 96 && travelled < 2 * kExitReach; ++step) {
    const ObjectSurfaceQuery q = dist.query(state, p);
    if (!entered) {  // free space: a step of |signed distance| reaches the surface at most
      if (travelled > kExitReach) return std::nullopt;
      entered = q.signed_distance > -kClose;
    } else if (q.signed_distance < kClose && q.normal.dot(e) > 0) {  // at a face that lets the ray out
      return Plane{q.closest, q.normal};
    }
    const double stride = std::max(std::abs(q.signed_distance), kClose);
    p += stride * e;
    travelled += stride;
  }
  return std::nullopt;
}

}  // namespace bimart
