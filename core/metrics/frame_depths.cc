#include "core/metrics/frame_depths.h"

#include <algorithm>
#include <limits>
#include <string>

#include <ATen/ATen.h>

#include "core/util/error.h"

namespace bimart {

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
  const double* s = states.data_ptr<double>();
  const double* x = vertices.data_ptr<double>();
  Points3 pts(2 * v, 3);
  for (int64_t t = 0; t < n; ++t) {
    const ObjectState state = ObjectState::from_row(s + 7 * t);
    for (int h = 0; h < 2; ++h)
      std::copy_n(x + ((h * n + t) * v) * 3, v * 3, pts.data() + h * v * 3);
    if (v == 0) continue;
    out.top[static_cast<size_t>(t)] = distance.max_signed_distance(state, pts, ObjectPart::Top);
    out.bottom[static_cast<size_t>(t)] = distance.max_signed_distance(state, pts, ObjectPart::Bottom);
  }
  return out;
}

}  // namespace bimart
