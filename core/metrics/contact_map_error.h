// CM (DESIGN §6): the contact map implied by the generated hands' J keypoints (core/
// features/contact_map.h) against the contact map that conditioned them: mean absolute
// difference over 2 × 1024 entries and all frames of one sequence, in metres (× 100 for
// the table); averaged over sequences.
#pragma once

#include <ATen/core/Tensor.h>

#include "core/object/articulated_object.h"

namespace bimart {

// `states` [N, 7]; `hit_indices` [N, 1024] int64 (an encoder's basis_hit_indices);
// `keypoints_world` [2, N, J, 3]; `conditioning` [N, 2, 1024] metres.
double contact_map_error(const ArticulatedObject& object, const at::Tensor& states,
                         const at::Tensor& hit_indices, const at::Tensor& keypoints_world,
                         const at::Tensor& conditioning);

}  // namespace bimart
