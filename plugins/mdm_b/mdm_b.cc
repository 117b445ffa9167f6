// motion.mdm_b: the MDM-B baseline (paper §4, "Baselines"; docs/baselines.md). MDM (Tevet
// et al. 2023) with its text condition replaced by the object trajectory: one transformer
// diffusion model over the MANO representation of both hands (as MANO-Rep), conditioned on
// the object features (NP-BPS and G) and nothing else — no contact maps, no contact
// guidance, no refinement. Trained with `bimart train motion models/baselines/mdm_b.yaml`
// (`representation: mano`, `condition: none`); the hands come from the hand model as
// motion.diffusion_mano's do, so every stage after it runs unchanged.
#include <chrono>

#include "core/diffusion/model_kind.h"
#include "core/pipeline/plugin.h"
#include "plugins/diffusion/mano_samples.h"
#include "plugins/diffusion/model_params.h"
#include "stages/motion_generator.h"

namespace bimart {
namespace {

class MdmB : public MotionGenerator {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<MotionGenerator>(
        "mdm_b", "MDM-B baseline: MANO hands from one diffusion model conditioned on the object only");
    diffusion_plugin::declare_sampling_params(s, "models/baselines/mdm_b.npz");
    diffusion_plugin::declare_mano_hands(s);
    return s;
  }

  explicit MdmB(const Params& p) : s_(diffusion_plugin::read_sampling_params(p)), hands_(p) {
    s_.options.cfg_lambda = 0;     // nothing to guide towards: the only condition is the object
    s_.options.use_contact = false;
    diffusion::check_sampling_stage(s_.model->info(), s_.model->path(), "motion.mdm_b");
  }

  void run(StageIO& io) override {
    const auto t0 = std::chrono::steady_clock::now();
    diffusion_plugin::check_encoder(*s_.model, io);
    if (io.has("guidance"))
      throw Error("motion.mdm_b takes no guidance: MDM-B is the diffusion model alone (remove the guidance stage)");
    const at::Tensor M = s_.model->generate(io.in<at::Tensor>("object_features"), io.in<at::Tensor>("global_states"),
                                            {}, nullptr, s_.options, diffusion_plugin::stage_generator(io));
    hands_.write(io, M, "motion.mdm_b", t0);
  }

 private:
  diffusion_plugin::Sampling s_;
  diffusion_plugin::ManoHands hands_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::MdmB)
