// What the motion model samples (TrainConfig::representation, ModelInfo::representation):
//   "keypoints"  X = [H | D], 1200 numbers per frame (paper §3.1; the method),
//   "mano"       MANO-Rep, 294 per frame (core/features/mano_representation.h; the paper's
//                Table 3 ablation row), turned into hands by the hand model, no keypoint fit.
// The contact model samples contact maps and has no representation ("keypoints" is stored).
#pragma once

#include <string>

namespace bimart::diffusion {

inline constexpr const char* kKeypointsRepresentation = "keypoints";
inline constexpr const char* kManoRepresentation = "mano";

// Throws bimart::Error naming the value and the known names.
void check_representation_name(const std::string& name);
// The motion model's sample size per frame: 1200 or 294.
int motion_sample_size(const std::string& representation);
// "keypoints (X = [H | D])" or "mano (MANO-Rep)": for messages.
std::string describe_representation(const std::string& representation);

}  // namespace bimart::diffusion
