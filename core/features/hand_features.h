// Hand features X = [H | D] (paper §3.1, DESIGN §4): per hand J = 100 surface keypoints H
// and, per keypoint, the vector D to the nearest object vertex (object posed at the
// frame's hinge angle), both in the canonical object frame. Per frame 1200 numbers:
// [H_left (300), H_right (300), D_left (300), D_right (300)], each block J rows of xyz.
#pragma once

#include <utility>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/object/articulated_object.h"

namespace bimart {

constexpr int kHandKeypoints = 100;
constexpr int kHandFeatureSize = 4 * 3 * kHandKeypoints;  // 1200

// X [N, 1200] float32 from posed hand vertices in the world frame [2, N, V, 3], the
// keypoint vertex ids (HandModel::keypoints, J = 100), the object and its states [N, 7].
at::Tensor hand_features(const at::Tensor& hand_vertices_world, const std::vector<int>& keypoint_ids,
                         const ArticulatedObject& object, const at::Tensor& states);

// The inverse mapping: X [N, 1200] (canonical frame) back to the world frame.
struct HandKeypointsWorld {
  at::Tensor positions;   // [2, N, J, 3] keypoints H, world frame
  at::Tensor directions;  // [2, N, J, 3] vectors D, world frame (rotated, not translated)
};
HandKeypointsWorld hand_features_to_world(const at::Tensor& features, const at::Tensor& states);

// Splits X [N, 1200] into H [2, N, J, 3] and D [2, N, J, 3] (frame unchanged); and back.
std::pair<at::Tensor, at::Tensor> split_hand_features(const at::Tensor& features);
at::Tensor join_hand_features(const at::Tensor& positions, const at::Tensor& directions);

}  // namespace bimart
