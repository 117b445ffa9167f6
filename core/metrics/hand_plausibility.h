// Hand plausibility (ours, issue 38): a frame is implausible when a hand has a finger joint
// bent outside its anatomical range or two of its fingers inside each other. The joints
// come from the posed vertices by the hand model's joint regressor, so the measure needs
// nothing but the vertices every metric uses, and it does not depend on how the pose was
// parameterised.
//   Bends: at each finger's MCP, PIP and DIP joint the flexion (about the hand's lateral
//   axis, + towards the palm) and at the MCP the abduction (out of the flexion plane), from
//   the bones' directions; the thumb's MCP and IP bends unsigned. The ranges (degrees,
//   kFingerLimits) are the ranges of motion usually quoted for the fingers (flexion MCP
//   0-90, PIP 0-110, DIP 0-90, MCP hyperextension to about 30, abduction about 20-30;
//   thumb MCP 0-60, IP 0-80) widened by a margin: joints regressed from a skinned mesh
//   are not exact, and a measure that flags ordinary grasps would say nothing.
//   Crossed fingers: the bones of two different fingers (capsules along MCP-PIP-DIP-tip)
//   closer than kCrossedGap: fingers about 1.6 cm thick, so their skins overlap by half.
#pragma once

#include <array>
#include <string>

#include <ATen/core/Tensor.h>
#include <Eigen/Core>

#include "core/hand/hand_model.h"
#include "core/metrics/frame_count.h"

namespace bimart {

struct JointRange {
  double lo, hi;  // degrees
};
struct FingerLimits {
  JointRange mcp_flex{-35, 105}, mcp_abduct{-45, 45}, pip_flex{-15, 125}, dip_flex{-25, 100};
  double thumb_mcp = 95, thumb_ip = 105;  // unsigned bend, degrees
};
inline constexpr FingerLimits kFingerLimits{};
constexpr double kCrossedGap = 0.008;  // m between the bone axes of two fingers

// One hand in one frame: joints [16, 3] (MANO order) and fingertips [5, 3] (thumb, index,
// middle, ring, pinky), world frame; hand 0 left, 1 right. Empty when plausible, else what
// is wrong ("index PIP bent backwards 32°", "middle and ring cross").
std::string implausibility(const Eigen::Matrix<double, 16, 3>& joints, const Eigen::Matrix<double, 5, 3>& tips, int hand);

// Frames (of [2, N, V, 3] vertices posed with `models` {left, right}) where a hand is
// implausible; `first_reason` (optional) gets the first frame's reason.
FrameCount implausible_frames(const at::Tensor& vertices, const std::array<const HandModel*, 2>& models,
                              std::string* first_reason = nullptr);

}  // namespace bimart
