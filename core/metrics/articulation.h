// Art (DESIGN §6): among frames t where the hinge angle changes by more than 0.001 rad from
// t to t+1, the frames where some hand vertex has signed distance > -5 mm to the top part
// alone (a vertex inside the top part counts). The last frame is never considered.
#pragma once

#include <vector>

#include <ATen/core/Tensor.h>

#include "core/metrics/frame_count.h"
#include "core/metrics/frame_depths.h"

namespace bimart {

constexpr double kAngleChange = 0.001;  // rad

// Per frame t of `states` [N, 7]: |angle(t+1) - angle(t)| > 0.001 rad.
std::vector<bool> angle_changing_frames(const at::Tensor& states);

FrameCount articulation_frames(const FrameDepths& depths, const std::vector<bool>& changing);

}  // namespace bimart
