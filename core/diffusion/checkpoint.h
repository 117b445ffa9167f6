// Model checkpoints (.npz, docs/training.md "Checkpoint file"): everything a stage needs to
// sample — network configuration and weights (EMA weights for sampling), noise schedule,
// normalisation statistics, the BPS basis and encoder variant the model was trained with,
// the hand keypoint ids, the training config and a fingerprint of the training data — and,
// in training checkpoints, what `bimart train --resume` needs to continue the identical
// run (raw weights, Adam moments, step). Written atomically.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/data/normalization.h"
#include "core/diffusion/denoiser.h"

namespace bimart::diffusion {

inline constexpr const char* kCheckpointFormat = "bimart-diffusion-checkpoint";
inline constexpr std::int64_t kCheckpointVersion = 1;

using TensorMap = std::map<std::string, at::Tensor>;

// What the model was trained with; a stage using it must agree (check_compatible).
struct ModelInfo {
  DenoiserConfig network;
  std::string schedule = "squaredcos_cap_v2";
  int diffusion_steps = 50;
  double schedule_shift = 1;       // make_schedule's shift (1 = none)
  std::string variant = "np_bps";  // encoder of O (bps_variant_name)
  // The motion model's sample (core/diffusion/representation.h); files without it: "keypoints".
  std::string representation = "keypoints";
  // The motion model's second condition (representation.h); files without it: "contact".
  std::string condition = "contact";
  at::Tensor basis_points;         // [1024, 3] float32, encoder space
  std::vector<std::int64_t> keypoints;  // J = 100 hand keypoint vertex ids
  NormalizationStats normalization;
  std::string config_text;         // the training configuration (YAML)
  std::string data_fingerprint;    // of the training data (see training.h)
};

// Training state for an exact resume. No random state: every draw of a training step is
// seeded from (config seed, step, rank) (core/diffusion/training.cc).
struct TrainState {
  std::int64_t step = 0;           // optimizer steps done
  TensorMap weights;               // raw (non-EMA) parameters
  TensorMap adam_exp_avg, adam_exp_avg_sq;
  std::int64_t adam_step = 0;
  double best_validation = 0;      // NaN before the first validation
};

struct Checkpoint {
  ModelInfo info;
  TensorMap weights;               // used for sampling: EMA weights when trained with EMA
  std::optional<TrainState> train;
};

void save_checkpoint(const Checkpoint& checkpoint, const std::string& path);
// Throws bimart::Error naming the file: not a checkpoint, newer version, truncated or
// damaged file, missing or malformed entries.
Checkpoint load_checkpoint(const std::string& path);

// Named parameters and buffers of a module, detached copies.
TensorMap state_of(const torch::nn::Module& module);
// Copies `weights` into the module; throws bimart::Error naming `what` and the first
// missing, unexpected or differently shaped entry.
void load_state(torch::nn::Module& module, const TensorMap& weights, const std::string& what);

// The J = 100 keypoint vertex ids of the hand model the metrics pose with
// (posing_hand_model_files, core/metrics/hand_vertices.h), checked by model_keypoints: what
// a model is trained with and what a stage compares a checkpoint against.
std::vector<std::int64_t> posing_keypoint_ids();

// A denoiser built from the checkpoint's config with its sampling weights, in eval mode.
Denoiser make_denoiser(const Checkpoint& checkpoint, const std::string& what);

// Throws bimart::Error naming `what` (the checkpoint) and each thing that differs from
// what the caller runs with: model kind, encoder variant, basis points (max difference),
// keypoint ids, hand representation. An empty model, variant or representation, an
// undefined basis or empty keypoints is not checked.
void check_compatible(const ModelInfo& info, const std::string& what, const std::string& model,
                      const std::string& variant, const at::Tensor& basis_points,
                      const std::vector<std::int64_t>& keypoints, const std::string& representation = "");

}  // namespace bimart::diffusion
