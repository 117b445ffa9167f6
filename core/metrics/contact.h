// Con (DESIGN §6): among frames t where the object moves (some vertex of either part moves
// more than 1e-5 m from t to t+1), the frames where some hand vertex has signed distance
// > -5 mm to the whole object. The last frame has no successor and is never considered.
#pragma once

#include <vector>

#include <ATen/core/Tensor.h>

#include "core/metrics/frame_count.h"
#include "core/metrics/frame_depths.h"
#include "core/object/articulated_object.h"

namespace bimart {

constexpr double kContactDistance = 0.005;  // m: a vertex closer than this (or inside) touches
constexpr double kObjectMotion = 1e-5;      // m: the object moves when a vertex moves more

// Per frame t of `states` [N, 7]: does some object vertex move more than 1e-5 m to t+1.
std::vector<bool> object_moving_frames(const ArticulatedObject& object, const at::Tensor& states);

FrameCount contact_frames(const FrameDepths& depths, const std::vector<bool>& moving);

}  // namespace bimart
