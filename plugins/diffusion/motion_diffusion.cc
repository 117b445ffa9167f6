// motion.diffusion: hand keypoints and direction vectors X = [H | D] sampled from the
// motion diffusion model, conditioned on the contact maps (or the null token), with
// classifier-free guidance and an optional guidance strategy at every step (DESIGN §5).
#include <fmt/format.h>

#include <chrono>

#include "core/diffusion/representation.h"
#include "core/pipeline/plugin.h"
#include "core/util/log.h"
#include "model_params.h"
#include "stages/motion_generator.h"

namespace bimart {
namespace {

class MotionDiffusion : public MotionGenerator {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<MotionGenerator>("diffusion", "hand motion X from the motion diffusion model");
    diffusion_plugin::declare_sampling_params(s, "models/motion.npz");
    s.param("cfg", 0.5, "classifier-free guidance λ_f: (1 + λ)·cond − λ·uncond; 0 = off")
        .param("use_contact", true, "condition on the contact maps; false = the null token (\"w/o C\")")
        .optional_input<at::Tensor>("contact_maps_samples",
                                    "[S, N, 2, 1024]: one contact map per sample (contact.diffusion's samples)")
        .optional_input<std::string>("contact_model",
                                     "the contact model that sampled the maps; refused unless it was trained on "
                                     "the same encoder variant and with G as this model was, or both without")
        .output<at::Tensor>("hand_keypoints_samples", "[S, N, 1200] float32: every sample (S = samples)");
    return s;
  }

  explicit MotionDiffusion(const Params& p) : s_(diffusion_plugin::read_sampling_params(p)) {
    s_.options.cfg_lambda = p.number("cfg");
    s_.options.use_contact = p.boolean("use_contact");
    if (s_.model->info().network.model != "motion")
      throw Error(s_.model->path() + " is a " + s_.model->info().network.model + " model, not a motion model");
    if (s_.model->info().representation != diffusion::kKeypointsRepresentation)
      throw Error("motion.diffusion samples keypoints X = [H | D], but " + s_.model->path() + " samples " +
                  diffusion::describe_representation(s_.model->info().representation) +
                  ": use motion.diffusion_mano for it");
    diffusion::check_compatible(s_.model->info(), s_.model->path(), "motion", "", {},
                                diffusion::posing_keypoint_ids(), diffusion::kKeypointsRepresentation);
  }

  void run(StageIO& io) override {
    const auto t0 = std::chrono::steady_clock::now();
    diffusion_plugin::check_encoder(*s_.model, io);
    const at::Tensor C = diffusion_plugin::contact_condition(*s_.model, s_.options, io, "motion.diffusion");
    const Guidance* guidance = nullptr;
    if (io.has("guidance")) guidance = io.in<std::shared_ptr<const Guidance>>("guidance").get();
    const at::Tensor X = s_.model->generate(io.in<at::Tensor>("object_features"), io.in<at::Tensor>("global_states"), C,
                                            guidance, s_.options, diffusion_plugin::stage_generator(io));
    log::info("motion.diffusion: {} frames x {} samples in {:.2f} s", X.size(1), X.size(0),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    io.out("hand_keypoints", X[0].contiguous());
    io.out("hand_keypoints_samples", X);
  }

 private:
  diffusion_plugin::Sampling s_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::MotionDiffusion)
