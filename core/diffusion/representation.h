// What the motion model samples (TrainConfig::representation, ModelInfo::representation):
//   "keypoints"  X = [H | D], 1200 numbers per frame (paper §3.1; the method),
//   "mano"       MANO-Rep, 294 per frame (core/features/mano_representation.h; the paper's
//                Table 3 ablation row), turned into hands by the hand model, no keypoint fit.
//   "joints"     both hands' 16 MANO joint positions, 96 per frame (MANO-Rep's joint columns;
//                OMOMO-B's first stage, docs/baselines.md).
// And what a motion model is conditioned on besides the object (ModelInfo::condition):
//   "contact"    the contact maps C (the method; a null token when dropped),
//   "none"       nothing (MDM-B, OMOMO-B's first stage),
//   "joints"     the joint positions of both hands, 96 per frame (OMOMO-B's second stage).
// The contact model samples contact maps and has no representation ("keypoints" is stored).
#pragma once

#include <string>

namespace bimart::diffusion {

inline constexpr const char* kKeypointsRepresentation = "keypoints";
inline constexpr const char* kManoRepresentation = "mano";
inline constexpr const char* kJointsRepresentation = "joints";
inline constexpr const char* kContactCondition = "contact";
inline constexpr const char* kNoCondition = "none";
inline constexpr const char* kJointsCondition = "joints";

// Throws bimart::Error naming the value and the known names.
void check_representation_name(const std::string& name);
// The motion model's sample size per frame: 1200, 294 or 96.
int motion_sample_size(const std::string& representation);
// Throws bimart::Error naming the value and the known names.
void check_condition_name(const std::string& name);
// The width of a motion model's second condition per frame: 2048 (C), 0 or 96.
int condition_size(const std::string& condition);
// "keypoints (X = [H | D])" or "mano (MANO-Rep)": for messages.
std::string describe_representation(const std::string& representation);
// "the contact maps C", "nothing but the object", "the joint positions": for messages.
std::string describe_condition(const std::string& condition);

}  // namespace bimart::diffusion
