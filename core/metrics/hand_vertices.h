// The hand points every metric works on (DESIGN §6): both hands' mesh vertices per frame in
// the world frame, and the J surface keypoints for the contact-map measure.
#pragma once

#include <array>
#include <memory>
#include <string>

#include <ATen/core/Tensor.h>

#include "core/hand/hand_model.h"
#include "core/hand/hand_motion.h"

namespace bimart {

// [2, N, V, 3] float32, world frame: `motion.vertices` when present, otherwise posed with
// batched LBS (core/hand/lbs_torch.h) from the shipped models
// models/hand/mano_{left,right}.npz (found with core/util/data_path.h; loaded once), or
// the models set with set_posing_hand_models.
at::Tensor hand_vertices(const HandMotion& motion);

// Pose with these hand model files from now on (e.g. a user's converted MANO, which ARCTIC
// data needs); both empty: back to the shipped models. Throws bimart::Error for a file that
// does not load or a swapped side. Thread-safe.
void set_posing_hand_models(const std::string& left_npz, const std::string& right_npz);
// The files hand_vertices poses with now: {left, right}.
std::array<std::string, 2> posing_hand_model_files();
// Those models, loaded (shared, loaded once per setting).
std::shared_ptr<const std::array<HandModel, 2>> posing_hand_models();

// [2, N, J, 3] float32: the J = 100 surface keypoints (the model's keypoint vertex ids)
// taken from hand_vertices(motion).
at::Tensor hand_keypoints(const HandMotion& motion);

}  // namespace bimart
