// The object condition a denoiser reads per frame (DESIGN §5): [O | G], 3072 + 7 = 3079
// numbers (the method), or O alone, 3072 (the paper's Table 3 "NP-BPS w/o G" row; training
// config `network.global_states: false`). A model's DenoiserConfig::object_condition_size
// says which; checkpoints store it (and, since the w/o G models, `network/global_states`).
#pragma once

#include <string>

#include <ATen/core/Tensor.h>

#include "core/diffusion/denoiser.h"

namespace bimart {
struct NormalizationStats;
}

namespace bimart::diffusion {

inline constexpr int kObjectFeatureSize = 1024 * 3;  // O per frame
inline constexpr int kGlobalStateSize = 7;           // G per frame

// 3079 with G, 3072 without.
int object_condition_size(bool global_states);
// Whether `network` reads G. Throws bimart::Error for an object condition that is neither
// 3079 nor 3072 wide.
bool reads_global_states(const DenoiserConfig& network);
// "with G" / "without G".
std::string global_states_name(bool global_states);

// What `network` reads: stats.normalize_object(O, G) [..., 3079], without G's 7 columns when
// the network does not read G [..., 3072]. O [..., 1024, 3], G [..., 7]. The statistics
// always cover [O | G], so one normalisation serves both kinds of model.
at::Tensor model_object_condition(const DenoiserConfig& network, const NormalizationStats& stats,
                                  const at::Tensor& object_features, const at::Tensor& global_states);

}  // namespace bimart::diffusion
