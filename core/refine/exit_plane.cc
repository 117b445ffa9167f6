#include "core/refine/exit_plane.h"

#include <algorithm>

namespace bimart {

Eigen::Vector3d exit_direction(const Points3& v, const std::vector<std::pair<int, ObjectSurfaceQuery>>& near) {
  Eigen::Vector3d sum_in = Eigen::Vector3d::Zero();
  int n_in = 0;
  for (const auto& [i, q] : near)
    if (q.signed_distance > 0) sum_in += v.row(i).transpose(), ++n_in;
  const int n_out = static_cast<int>(v.rows()) - n_in;
  if (n_in == 0 || n_out == 0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d sum_out = v.colwise().sum().transpose() - sum_in;  // the rest of the hand
  const Eigen::Vector3d e = sum_out / n_out - sum_in / n_in;
  return e.norm() > 1e-9 ? Eigen::Vector3d(e.normalized()) : Eigen::Vector3d::Zero();
}

// Sphere tracing: a step of the signed distance never crosses the surface.
std::optional<Plane> exit_plane(const ObjectDistance& dist, const ObjectState& state, Eigen::Vector3d p,
                                const Eigen::Vector3d& e) {
  constexpr double kClose = 2e-4;  // m
  double travelled = 0;
  for (int step = 0; step < 32 && travelled < kExitReach; ++step) {
    const ObjectSurfaceQuery q = dist.query(state, p);
    if (q.signed_distance < kClose) return Plane{q.closest, q.normal.dot(e) > 0 ? q.normal : e};
    const double stride = std::max(q.signed_distance, kClose);
    p += stride * e;
    travelled += stride;
  }
  return std::nullopt;
}

}  // namespace bimart
