// Batched posing with libtorch: many frames of an object state at once (DESIGN §4).
#pragma once

#include <ATen/core/Tensor.h>

#include "core/object/articulated_object.h"

namespace bimart {

struct PosedObjectBatch {
  at::Tensor top;     // [N, Vt, 3] world frame
  at::Tensor bottom;  // [N, Vb, 3] world frame
};

// `states` is [N, 7] (float32 or float64; the output has the same dtype):
// [angle, rx, ry, rz, tx, ty, tz]. Throws bimart::Error on a wrong shape or a non-finite value.
PosedObjectBatch pose_object_batch(const ArticulatedObject& object, const at::Tensor& states);

// Batched Rodrigues: [N, 3] axis-angle -> [N, 3, 3], robust at zero angle.
at::Tensor axis_angle_to_matrix_batch(const at::Tensor& axis_angle);

// Canonical-frame points [N, K, 3] (articulation already applied) to the world frame by each
// frame's root pose of `states` [N, 7]: float64 out.
at::Tensor canonical_to_world_batch(const at::Tensor& points, const at::Tensor& states);

}  // namespace bimart
