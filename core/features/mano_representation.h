// MANO-Rep (paper §4.4, Table 3): the motion model's alternative sample to X = [H | D].
// Per frame and hand, in the canonical object frame (root pose removed, as X):
//   [R6 (16 × 6) | wrist (3) | joints (16 × 3)] = 147 numbers; per frame [left | right] = 294.
// R6: each MANO joint's rotation as the first two columns of its matrix (Zhou et al. 2019),
// column 0 then column 1; joint 0 is the global (wrist) rotation, turned into the canonical
// frame, joints 1..15 the finger rotations relative to their parents (frame-free).
// wrist: the wrist joint's position J0(β) + trans. MANO rotates the hand about J0(β), so the
// wrist transforms as a point where `trans` does not; decoding recovers
// trans = wrist_world − J0(β).
// joints: the 16 posed joint positions (joint 0 is the wrist again). Auxiliary: decoding
// reads only R6 and the wrist.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/hand/hand_model.h"
#include "core/hand/hand_motion.h"

namespace bimart {

constexpr int kManoRepHandSize = HandModel::kNumJoints * 6 + 3 + HandModel::kNumJoints * 3;  // 147
constexpr int kManoRepSize = 2 * kManoRepHandSize;                                           // 294
constexpr int kManoRepWrist = HandModel::kNumJoints * 6;  // offset of the wrist within a hand's block
constexpr int kManoRepJoints = kManoRepWrist + 3;         // offset of the joints
constexpr int kManoRepJointsSize = 2 * HandModel::kNumJoints * 3;  // 96: both hands' joints

// [N, 294] float32 from the hands' parameters (world frame), posed with `models` {left,
// right} for the joints, and the object states [N, 7].
at::Tensor mano_representation(const std::array<const HandModel*, 2>& models, const HandMotion& motion,
                               const at::Tensor& states);

// The inverse: [N, 294] (canonical frame) and the states [N, 7] to world-frame parameters
// with shape β = `shapes` [10] per hand; rotations are orthonormalised first (Gram-Schmidt
// of the two columns). Vertices are not posed.
HandMotion hands_from_mano_representation(const std::array<const HandModel*, 2>& models, const at::Tensor& rep,
                                          const at::Tensor& states, const std::array<at::Tensor, 2>& shapes);

// The joint columns of MANO-Rep [..., 294] -> [..., 96] (left hand's 16 joints, then the
// right's), and the column indices they come from (for statistics).
at::Tensor mano_representation_joints(const at::Tensor& rep);
const std::vector<std::int64_t>& mano_representation_joint_columns();

// Rotation matrices [..., 3, 3] -> [..., 6] (columns 0 and 1); and back, orthonormalising.
at::Tensor rotation_to_6d(const at::Tensor& rotations);
at::Tensor rotation_from_6d(const at::Tensor& six);

}  // namespace bimart
