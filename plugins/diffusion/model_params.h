// Parameters shared by the diffusion stages (contact.diffusion, motion.diffusion): the
// checkpoint, the sampler and the number of samples.
#pragma once

#include <string>

#include <ATen/CPUGeneratorImpl.h>

#include "core/diffusion/generation.h"
#include "core/diffusion/object_condition.h"
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

// Before sampling: refuses a model trained on another encoder variant than the pipeline's
// encoder stage gives (naming the model file and its variant, the stage and its variant),
// then compares the basis points when they are wired (diffusion::check_compatible).
inline void check_encoder(const diffusion::DiffusionModel& model, StageIO& io) {
  const diffusion::ModelInfo& info = model.info();
  if (io.has("encoder_variant")) {
    const std::string& variant = io.in<std::string>("encoder_variant");
    if (variant != info.variant)
      throw Error(model.path() + " is a " + info.network.model + " model trained on " + info.variant +
                  " features, but this pipeline's encoder stage '" + io.source("encoder_variant") + "' gives " +
                  variant + " features: use encoder." + info.variant + " there, or a model trained with 'variant: " +
                  variant + "'");
  }
  if (io.has("basis_points"))
    diffusion::check_compatible(info, model.path(), info.network.model, "", io.in<at::Tensor>("basis_points"), {});
}

// Refuses contact maps sampled by a contact model of another Table 3 row than the motion
// model's: another encoder variant, or G read by one and not the other.
inline void check_contact_model(const diffusion::DiffusionModel& motion, const diffusion::DiffusionModel& contact) {
  const auto row = [](const diffusion::ModelInfo& i) {
    return i.variant + ", " + diffusion::global_states_name(diffusion::reads_global_states(i.network));
  };
  if (row(motion.info()) != row(contact.info()))
    throw Error("the motion model " + motion.path() + " (" + row(motion.info()) + ") would be conditioned on maps of the contact model " +
                contact.path() + " (" + row(contact.info()) + "): use models trained alike");
}

// The contact condition of a motion stage: one map per sample when the contact stage drew
// as many, else the one map, else (use_contact off) none. Refuses maps of a contact model
// of another row (check_contact_model) when they come from it.
inline at::Tensor contact_condition(const diffusion::DiffusionModel& motion, const diffusion::GenerateOptions& options,
                                    StageIO& io, const std::string& stage) {
  if (!options.use_contact) return {};
  const char* port = io.has("contact_maps_samples") &&
                             io.in<at::Tensor>("contact_maps_samples").size(0) == options.samples
                         ? "contact_maps_samples"
                         : "contact_maps";
  if (!io.has(port))
    throw Error(stage + ": use_contact is on but no contact_maps are wired (set use_contact: false for the null token)");
  // The maps' own model only (a pipeline may hold other contact stages).
  if (io.has("contact_model") && io.source("contact_model") == io.source(port))
    check_contact_model(motion, *diffusion::DiffusionModel::load(io.in<std::string>("contact_model")));
  return io.in<at::Tensor>(port);
}

// libtorch generator seeded from the stage's own seeded stream.
inline at::Generator stage_generator(StageIO& io) { return at::detail::createCPUGenerator(io.rng()()); }

}  // namespace bimart::diffusion_plugin
