// Per frame, the deepest hand vertex of both hands against each object part: the one pass
// over signed distances (core/object/object_distance.h) that Pen, Con and Art share.
#pragma once

#include <vector>

#include <ATen/core/Tensor.h>

#include "core/object/object_distance.h"

namespace bimart {

// m: cavity depths up to this read 0 (only Cavity's 1 cm threshold reads them).
constexpr double kCavityFloor = 0.005;

struct FrameDepths {
  // max over both hands' vertices of the signed distance (m, > 0 inside) to each part.
  std::vector<double> top, bottom;
  // The deepest hand vertex in a cavity: outside the object, inside a part's convex hull
  // (ObjectDistance::max_cavity_depth; m, 0 when none or up to 5 mm).
  std::vector<double> cavity;
  // The whole object (union of the parts).
  double whole(size_t t) const { return top[t] > bottom[t] ? top[t] : bottom[t]; }
  size_t size() const { return top.size(); }
};

// `states` [N, 7], `vertices` [2, N, V, 3] world frame.
FrameDepths frame_depths(const ObjectDistance& distance, const at::Tensor& states,
                         const at::Tensor& vertices);

}  // namespace bimart
