// Contact maps C (paper eq. 4, DESIGN §4): per frame and hand, for each of the 1024 object
// vertices hit by the BPS basis (basis order), the distance to the nearest point of that
// hand (its mesh vertices for data and metrics, its J keypoints for guidance and CM).
// Distances are rigid-invariant: object and hand points only need to share a frame.
#pragma once

#include <ATen/core/Tensor.h>

#include "core/object/articulated_object.h"

namespace bimart {

// The hit vertices in the canonical frame, articulation applied: [N, 1024, 3] float32.
// `states` [N, 7]; `hit_indices` [N, 1024] int64 into [top; bottom] (an encoder's
// `basis_hit_indices`).
at::Tensor basis_hit_points(const ArticulatedObject& object, const at::Tensor& states,
                            const at::Tensor& hit_indices);

// C [N, 2, 1024]: min over each hand's points of the distance to each object point.
// `object_points` [N, 1024, 3]; `hand_points` [2, N, P, 3] (left, right), same frame.
// Float32 or float64 in, same dtype out. The nearest pairs come from one k-d tree per frame
// and hand (frames in parallel); their distances are formed with libtorch, so the result is
// differentiable in both arguments (guidance) like a minimum over all pairs.
at::Tensor contact_maps(const at::Tensor& object_points, const at::Tensor& hand_points);
// The pairwise path regardless of grad: the second implementation, for cross-checks.
at::Tensor contact_maps_exhaustive(const at::Tensor& object_points, const at::Tensor& hand_points);

// C [N, 2, 1024] of hands given in the world frame (`world_hand_points` [2, N, P, 3]): the
// hit vertices (`hit_indices` [N, 1024]) posed by `states` [N, 7], then contact_maps. What
// the training data holds, and contact.ground_truth gives.
at::Tensor world_contact_maps(const ArticulatedObject& object, const at::Tensor& states, const at::Tensor& hit_indices,
                              const at::Tensor& world_hand_points);

}  // namespace bimart
