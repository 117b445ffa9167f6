#include "core/metrics/contact.h"

#include <ATen/ATen.h>

#include "core/object/object_state.h"
#include "core/util/error.h"

namespace bimart {

std::vector<bool> object_moving_frames(const ArticulatedObject& object, const at::Tensor& states_in) {
  const at::Tensor states = states_in.to(at::kCPU, at::kDouble).contiguous();
  if (states.dim() != 2 || states.size(1) != 7) throw Error("object states must be [N, 7]");
  const int64_t n = states.size(0);
  std::vector<bool> moving(static_cast<size_t>(n), false);
  const double* s = states.data_ptr<double>();
  PosedObject prev = pose_world(object, ObjectState::from_row(s));
  for (int64_t t = 0; t + 1 < n; ++t) {
    PosedObject next = pose_world(object, ObjectState::from_row(s + 7 * (t + 1)));
    const double top = prev.top.rows() ? (next.top - prev.top).rowwise().norm().maxCoeff() : 0.0;
    const double bottom = prev.bottom.rows() ? (next.bottom - prev.bottom).rowwise().norm().maxCoeff() : 0.0;
    moving[static_cast<size_t>(t)] = std::max(top, bottom) > kObjectMotion;
    prev = std::move(next);
  }
  return moving;
}

FrameCount contact_frames(const FrameDepths& depths, const std::vector<bool>& moving) {
  if (moving.size() != depths.size()) throw Error("contact: frame counts of depths and motion differ");
  FrameCount c;
  for (size_t t = 0; t < depths.size(); ++t) {
    if (!moving[t]) continue;
    ++c.frames;
    if (depths.whole(t) > -kContactDistance) ++c.hits;
  }
  return c;
}

}  // namespace bimart
