// Parameters shared by the diffusion stages (contact.diffusion, motion.diffusion): the
// checkpoint, the sampler and the number of samples.
#pragma once

#include <string>

#include <ATen/CPUGeneratorImpl.h>

#include "core/diffusion/generation.h"
#include "core/pipeline/stage.h"
#include "core/util/data_path.h"

namespace bimart::diffusion_plugin {

inline void declare_sampling_params(StageSpec& s, const char* default_checkpoint) {
  s.param("checkpoint", default_checkpoint, "model checkpoint (.npz; bimart train writes it)")
      .param("sampler", "ddpm", "ddpm (every step, the method's default) or ddim")
      .param("steps", 0, "DDIM steps (0 = every step of the schedule)")
      .param("eta", 0.0, "DDIM noise (0 = deterministic)")
      .param("samples", 1, "samples generated at once (batched); the first is the stage's main output")
      .param("overlap", 48, "frames shared by consecutive windows of a long sequence (fused at every denoising step)")
      .param("band", 0, "keep the lowest N DCT frequencies over each window's frames of every x0 prediction (0 = off)");
}

struct Sampling {
  std::shared_ptr<const diffusion::DiffusionModel> model;
  diffusion::GenerateOptions options;
};

inline Sampling read_sampling_params(const Params& p) {
  Sampling s;
  std::string path = p.string("checkpoint");
  s.model = diffusion::DiffusionModel::load(find_data_file(path));
  s.options.sampler.sampler = p.string("sampler");
  s.options.sampler.steps = static_cast<int>(p.integer("steps"));
  s.options.sampler.eta = p.number("eta");
  s.options.samples = static_cast<int>(p.integer("samples"));
  s.options.overlap = static_cast<int>(p.integer("overlap"));
  s.options.band = static_cast<int>(p.integer("band"));
  if (s.options.band < 0) throw Error("'band' must be 0 (off) or a number of frequencies, got " + std::to_string(s.options.band));
  diffusion::sampling_timesteps(s.model->schedule(), s.options.sampler);  // validates sampler and steps
  if (s.options.samples < 1 || s.options.samples > 1024)
    throw Error("'samples' must be in [1, 1024], got " + std::to_string(s.options.samples));
  return s;
}

// libtorch generator seeded from the stage's own seeded stream.
inline at::Generator stage_generator(StageIO& io) { return at::detail::createCPUGenerator(io.rng()()); }

}  // namespace bimart::diffusion_plugin
