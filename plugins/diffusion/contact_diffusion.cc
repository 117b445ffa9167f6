// contact.diffusion: bimanual contact maps C sampled from the contact diffusion model
// (DESIGN §2, §5; core/diffusion/generation.h).
#include <fmt/format.h>

#include <chrono>
#include <memory>

#include "core/diffusion/model_kind.h"
#include "core/directing/contact_rules.h"
#include "core/directing/kept_sample.h"
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
    s.optional_input<HandConstraints>("hand_constraints",
                                      "which part each hand touches, or that it stays off, over which frames "
                                      "(docs/directing.md): imposed on every denoising step's maps")
        .optional_input<ArticulatedObject>("object", "the object (needed with hand_constraints)")
        .optional_input<at::Tensor>("basis_hit_indices",
                                    "[N, 1024] int64: the object points of C (needed with hand_constraints)");
    s.output<at::Tensor>("contact_maps_samples", "[S, N, 2, 1024] float32, metres: every sample (S = samples)")
        .output<std::string>("contact_model", "the checkpoint sampled (motion.diffusion checks that it agrees with its own)");
    return s;
  }

  explicit ContactDiffusion(const Params& p) : s_(diffusion_plugin::read_sampling_params(p)) {
    diffusion::check_sampling_stage(s_.model->info(), s_.model->path(), "contact.diffusion");
  }

  void run(StageIO& io) override {
    const auto t0 = std::chrono::steady_clock::now();
    diffusion_plugin::check_encoder(*s_.model, io);
    const ConstraintChain constraint = constraints(io);
    const at::Tensor C = s_.model->generate(io.in<at::Tensor>("object_features"), io.in<at::Tensor>("global_states"),
                                            {}, nullptr, s_.options, diffusion_plugin::stage_generator(io),
                                            constraint.empty() ? nullptr : &constraint);
    log::info("contact.diffusion: {} frames x {} samples in {:.2f} s", C.size(1), C.size(0),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    io.out("contact_maps", C[0].contiguous());
    io.out("contact_maps_samples", C);
    io.out("contact_model", s_.model->path());
  }

 private:
  // The contact rules of hand_constraints, then a kept sample's maps (docs/directing.md).
  static ConstraintChain constraints(StageIO& io) {
    ConstraintChain chain;
    if (!io.has("hand_constraints")) return chain;
    const auto& c = io.in<HandConstraints>("hand_constraints");
    const std::int64_t N = io.in<at::Tensor>("object_features").size(0);
    if (!c.contacts.empty()) {
      if (!io.has("object") || !io.has("basis_hit_indices"))
        throw Error("contact.diffusion: hand_constraints need the object and basis_hit_indices wired");
      chain.add(std::make_shared<ContactRules>(c, io.in<ArticulatedObject>("object"), io.in<at::Tensor>("basis_hit_indices")));
    }
    if (c.keep) chain.add(kept_contact_maps(*c.keep, N));
    return chain;
  }

  diffusion_plugin::Sampling s_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::ContactDiffusion)
