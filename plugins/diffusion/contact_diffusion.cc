// contact.diffusion: bimanual contact maps C sampled from the contact diffusion model
// (DESIGN §2, §5; core/diffusion/generation.h).
#include <fmt/format.h>

#include <chrono>

#include "core/pipeline/plugin.h"
#include "core/util/log.h"
#include "model_params.h"
#include "stages/contact_generator.h"

namespace bimart {
namespace {

class ContactDiffusion : public ContactGenerator {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<ContactGenerator>("diffusion", "contact maps from the contact diffusion model");
    diffusion_plugin::declare_sampling_params(s, "models/contact.npz");
    s.output<at::Tensor>("contact_maps_samples", "[S, N, 2, 1024] float32, metres: every sample (S = samples)")
        .output<std::string>("contact_model", "the checkpoint sampled (motion.diffusion checks that it agrees with its own)");
    return s;
  }

  explicit ContactDiffusion(const Params& p) : s_(diffusion_plugin::read_sampling_params(p)) {
    if (s_.model->info().network.model != "contact")
      throw Error(s_.model->path() + " is a " + s_.model->info().network.model + " model, not a contact model");
  }

  void run(StageIO& io) override {
    const auto t0 = std::chrono::steady_clock::now();
    diffusion_plugin::check_encoder(*s_.model, io);
    const at::Tensor C = s_.model->generate(io.in<at::Tensor>("object_features"), io.in<at::Tensor>("global_states"),
                                            {}, nullptr, s_.options, diffusion_plugin::stage_generator(io));
    log::info("contact.diffusion: {} frames x {} samples in {:.2f} s", C.size(1), C.size(0),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    io.out("contact_maps", C[0].contiguous());
    io.out("contact_maps_samples", C);
    io.out("contact_model", s_.model->path());
  }

 private:
  diffusion_plugin::Sampling s_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::ContactDiffusion)
