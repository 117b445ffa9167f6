// Sampling a trained model over a whole sequence (DESIGN §2, §5): windows of the model's
// length cover the sequence with an overlap, all windows and samples are denoised as one
// batch and fused into one sequence at every step (so shared frames agree), the
// conditions are encoded once per window, and for the motion model classifier-free
// guidance runs both passes in one batched forward, with an optional guidance correction
// of the conditional x0 prediction at every step.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <ATen/core/Generator.h>
#include <ATen/core/Tensor.h>

#include "core/diffusion/checkpoint.h"
#include "core/diffusion/denoiser.h"
#include "core/diffusion/sampler.h"
#include "core/diffusion/schedule.h"
#include "stages/guidance.h"
#include "stages/sample_constraint.h"

namespace bimart::diffusion {

struct GenerateOptions {
  SamplerOptions sampler;   // ddpm (all steps) or ddim
  double cfg_lambda = 0.5;  // motion model: (1 + λ)·cond − λ·uncond; 0 = conditional only
  int samples = 1;          // batched
  int overlap = 48;         // frames shared by consecutive windows (fused at every step)
  bool use_contact = true;  // motion model: false = null contact token ("w/o C")
  int band = 0;             // keep the lowest `band` DCT frequencies over each window's frames of
                            // every x0 prediction (temporal_band.h); 0 = off
};

class DiffusionModel {
 public:
  // Loads (and caches by path and modification time) a checkpoint.
  static std::shared_ptr<const DiffusionModel> load(const std::string& path);
  explicit DiffusionModel(Checkpoint checkpoint, std::string path);

  const ModelInfo& info() const { return checkpoint_.info; }
  const std::string& path() const { return path_; }
  const NoiseSchedule& schedule() const { return schedule_; }
  int window() const { return checkpoint_.info.network.window; }
  // The denoiser (EMA weights), shared: for checks that call it step by step.
  Denoiser network() const { return net_; }

  // Generates S = options.samples samples for N frames.
  // object_features O [N, 1024, 3], global_states G [N, 7] (translation relative to any
  // fixed frame: each window subtracts its own first translation); contact_maps: the motion
  // model's second condition (ModelInfo::condition) — C [N, 2, 1024] or [S, N, 2, 1024] in
  // metres (undefined when use_contact is false), the joints [N, 96] or [S, N, 96] (m,
  // canonical) for a model conditioned on them, undefined for one conditioned on nothing.
  // Returns, denormalised: contact model C [S, N, 2, 1024] (m, clamped at 0); motion
  // model X [S, N, 1200] (m, canonical frame), or for a MANO-Rep model (which takes no
  // guidance) its sample [S, N, 294] (core/features/mano_representation.h), or for a joints
  // model the joints [S, N, 96].
  // `constraint` (optional) is imposed on every step's clean-sample prediction, after the
  // guidance, and on the result: contact model on C [B, T, 2048] (m), motion model on X
  // (stages/sample_constraint.h); a MANO-Rep model takes none.
  at::Tensor generate(const at::Tensor& object_features, const at::Tensor& global_states,
                      const at::Tensor& contact_maps, const Guidance* guidance, const GenerateOptions& options,
                      at::Generator gen, const SampleConstraint* constraint = nullptr) const;

  // The windows [start, start + length) covering N frames with the given overlap: starts
  // 0, W - overlap, ..., the last aligned to the end; one window [0, N) when N <= W.
  static std::vector<std::pair<std::int64_t, std::int64_t>> windows(std::int64_t frames, int window, int overlap);

 private:
  Checkpoint checkpoint_;
  std::string path_;
  NoiseSchedule schedule_;
  mutable Denoiser net_{nullptr};
};

}  // namespace bimart::diffusion
