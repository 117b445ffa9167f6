#include "core/metrics/articulation.h"

#include <cmath>

#include <ATen/ATen.h>

#include "core/metrics/contact.h"
#include "core/util/error.h"

namespace bimart {

std::vector<bool> angle_changing_frames(const at::Tensor& states_in) {
  const at::Tensor states = states_in.to(at::kCPU, at::kDouble).contiguous();
  if (states.dim() != 2 || states.size(1) != 7) throw Error("object states must be [N, 7]");
  const int64_t n = states.size(0);
  const double* s = states.data_ptr<double>();
  std::vector<bool> changing(static_cast<size_t>(n), false);
  for (int64_t t = 0; t + 1 < n; ++t)
    changing[static_cast<size_t>(t)] = std::abs(s[7 * (t + 1)] - s[7 * t]) > kAngleChange;
  return changing;
}

FrameCount articulation_frames(const FrameDepths& depths, const std::vector<bool>& changing) {
  if (changing.size() != depths.size()) throw Error("articulation: frame counts differ");
  FrameCount c;
  for (size_t t = 0; t < depths.size(); ++t) {
    if (!changing[t]) continue;
    ++c.frames;
    if (depths.top[t] > -kContactDistance) ++c.hits;
  }
  return c;
}

}  // namespace bimart
