#include "core/metrics/frame_depths.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <string>

#include <ATen/ATen.h>

#include "core/geometry/point_guard.h"
#include "core/util/error.h"

namespace bimart {
namespace {

// Diverged motion (NaN, or absurdly far) is reported with its frame, hand and vertex
// before any of it reaches CGAL.
void check_frame_points(const Points3& pts, int64_t v, int64_t t) {
  for (Eigen::Index i = 0; i < pts.rows(); ++i) {
    const Eigen::Vector3d p = pts.row(i).transpose();
    if (p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxCoordinate) continue;
    const char* side = i < v ? "left" : "right";
    throw Error(fmt::format("frame {}: {} hand vertex {} is ({:.6g}, {:.6g}, {:.6g}): {} (field 'hand_vertices', or "
                            "posed from '{}_rot', '{}_pose', '{}_trans', '{}_shape')",
                            t, side, i % v, p.x(), p.y(), p.z(),
                            p.allFinite() ? fmt::format("more than {:g} m from the origin", kMaxCoordinate)
                                          : std::string("not finite"),
                            side, side, side, side));
  }
}

}  // namespace

FrameDepths frame_depths(const ObjectDistance& distance, const at::Tensor& states_in,
                         const at::Tensor& vertices_in) {
  const at::Tensor states = states_in.to(at::kCPU, at::kDouble).contiguous();
  const at::Tensor vertices = vertices_in.to(at::kCPU, at::kDouble).contiguous();
  if (states.dim() != 2 || states.size(1) != 7) throw Error("object states must be [N, 7]");
  const int64_t n = states.size(0);
  if (vertices.dim() != 4 || vertices.size(0) != 2 || vertices.size(1) != n || vertices.size(3) != 3)
    throw Error("hand vertices must be [2, N, V, 3] with N = " + std::to_string(n) +
                " (the object's frames)");
  const int64_t v = vertices.size(2);
  FrameDepths out;
  out.top.assign(static_cast<size_t>(n), -std::numeric_limits<double>::infinity());
  out.bottom = out.top;
  out.cavity.assign(static_cast<size_t>(n), 0.0);
  const double* s = states.data_ptr<double>();
  const double* x = vertices.data_ptr<double>();
  Points3 pts(2 * v, 3);
  for (int64_t t = 0; t < n; ++t) {
    const ObjectState state = ObjectState::from_row(s + 7 * t);
    for (int h = 0; h < 2; ++h)
      std::copy_n(x + ((h * n + t) * v) * 3, v * 3, pts.data() + h * v * 3);
    if (v == 0) continue;
    check_frame_points(pts, v, t);
    out.top[static_cast<size_t>(t)] = distance.max_signed_distance(state, pts, ObjectPart::Top);
    out.bottom[static_cast<size_t>(t)] = distance.max_signed_distance(state, pts, ObjectPart::Bottom);
    out.cavity[static_cast<size_t>(t)] = distance.max_cavity_depth(state, pts, kCavityFloor);
  }
  return out;
}

}  // namespace bimart
