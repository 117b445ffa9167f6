// motion.diffusion_mano: the MANO-Rep motion model (the paper's Table 3 ablation row). It
// samples per hand the 6D rotations of the 16 MANO joints, the wrist position and the joint
// positions in the canonical frame (core/features/mano_representation.h), with contact
// conditioning and classifier-free guidance as motion.diffusion but no guidance strategy, and
// turns them into hands with the hand model (mano_samples.h).
#include <chrono>

#include "core/diffusion/model_kind.h"
#include "core/pipeline/plugin.h"
#include "mano_samples.h"
#include "model_params.h"
#include "stages/motion_generator.h"

namespace bimart {
namespace {

class MotionDiffusionMano : public MotionGenerator {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<MotionGenerator>(
        "diffusion_mano", "MANO hands from the MANO-Rep motion diffusion model (6D joint rotations, wrist, joints)");
    diffusion_plugin::declare_sampling_params(s, "models/motion_mano.npz");
    s.param("cfg", 0.5, "classifier-free guidance λ_f: (1 + λ)·cond − λ·uncond; 0 = off")
        .param("use_contact", true, "condition on the contact maps; false = the null token")
        .optional_input<at::Tensor>("contact_maps_samples",
                                    "[S, N, 2, 1024]: one contact map per sample (contact.diffusion's samples)")
        .optional_input<std::string>("contact_model",
                                     "the contact model that sampled the maps; refused unless it was trained on "
                                     "the same encoder variant and with G as this model was, or both without");
    diffusion_plugin::declare_mano_hands(s);
    return s;
  }

  explicit MotionDiffusionMano(const Params& p) : s_(diffusion_plugin::read_sampling_params(p)), hands_(p) {
    s_.options.cfg_lambda = p.number("cfg");
    s_.options.use_contact = p.boolean("use_contact");
    diffusion::check_sampling_stage(s_.model->info(), s_.model->path(), "motion.diffusion_mano");
  }

  void run(StageIO& io) override {
    const auto t0 = std::chrono::steady_clock::now();
    diffusion_plugin::check_encoder(*s_.model, io);
    if (io.has("guidance"))
      throw Error("motion.diffusion_mano takes no guidance: contact-map guidance corrects keypoints, and this model "
                  "samples MANO parameters (remove the guidance stage)");
    const at::Tensor C = diffusion_plugin::contact_condition(*s_.model, s_.options, io, "motion.diffusion_mano");
    const at::Tensor M = s_.model->generate(io.in<at::Tensor>("object_features"), io.in<at::Tensor>("global_states"),
                                            C, nullptr, s_.options, diffusion_plugin::stage_generator(io));
    hands_.write(io, M, "motion.diffusion_mano", t0);
  }

 private:
  diffusion_plugin::Sampling s_;
  diffusion_plugin::ManoHands hands_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::MotionDiffusionMano)
