// The J hand-surface keypoints of the hand representation (DESIGN §4): a fixed subset of
// hand-mesh vertices chosen by farthest-point sampling within each hand part.
#pragma once

#include <vector>

#include "core/hand/hand_model.h"

namespace bimart {

// Parts: each vertex belongs to the joint with its largest skinning weight (the wrist is the
// palm; 15 finger segments). Each part gets at least 2 keypoints, the rest in proportion to
// its surface area (largest remainder), capped by its vertex count. Within a part,
// farthest-point sampling starts at the vertex nearest the part's centroid (ties: lowest id).
// Deterministic, and the same for a hand and its mirror image. Returned in part order.
// Throws bimart::Error if J is smaller than 2 per non-empty part or larger than V.
std::vector<int> hand_keypoints(const HandModel& model, int J = 100);

// J of the hand representation (DESIGN §4).
constexpr int kNumKeypoints = 100;

// The keypoint ids every command uses, one rule for all: the model's stored
// `keypoint_verts`, else computed with hand_keypoints; exactly kNumKeypoints of them, else a
// bimart::Error.
std::vector<int> model_keypoints(const HandModel& model);

// The part (joint id) of every vertex: the argmax of its skinning weights, lowest on ties.
std::vector<int> hand_parts(const HandModel& model);

}  // namespace bimart
