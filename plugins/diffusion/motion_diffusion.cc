// motion.diffusion: hand keypoints and direction vectors X = [H | D] sampled from the
// motion diffusion model, conditioned on the contact maps (or the null token), with
// classifier-free guidance and an optional guidance strategy at every step (DESIGN §5).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <memory>

#include "core/diffusion/model_kind.h"
#include "core/diffusion/representation.h"
#include "core/directing/hand_pins.h"
#include "core/directing/kept_sample.h"
#include "core/features/contact_map.h"
#include "core/pipeline/plugin.h"
#include "core/util/data_path.h"
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
        .optional_input<HandConstraints>("hand_constraints",
                                         "pinned hand poses and hands kept off the object (docs/directing.md): "
                                         "imposed on every denoising step's keypoints")
        .optional_input<ArticulatedObject>("object", "the object (needed with hand_constraints)")
        .optional_input<at::Tensor>("object_states", "[N, 7] (needed with hand_constraints)")
        .optional_input<at::Tensor>("basis_hit_indices", "[N, 1024] int64 (needed with hand_constraints)")
        .param("pin_sigma", 4.0, "frames: a pinned frame's change also moves the frames around it (Gaussian)")
        .param("mano_left", "", "left hand model .npz for pinned wrists (empty: the shipped hand; as refine's)")
        .param("mano_right", "", "right hand model .npz for pinned wrists")
        .output<at::Tensor>("hand_keypoints_samples", "[S, N, 1200] float32: every sample (S = samples)");
    return s;
  }

  explicit MotionDiffusion(const Params& p) : s_(diffusion_plugin::read_sampling_params(p)) {
    s_.options.cfg_lambda = p.number("cfg");
    s_.options.use_contact = p.boolean("use_contact");
    pin_sigma_ = p.number("pin_sigma");
    if (!(pin_sigma_ >= 0)) throw Error("'pin_sigma' must be >= 0 (frames)");
    mano_[0] = p.string("mano_left");
    mano_[1] = p.string("mano_right");
    if (mano_[0].empty() != mano_[1].empty()) throw Error("give both mano_left and mano_right, or neither");
    diffusion::check_sampling_stage(s_.model->info(), s_.model->path(), "motion.diffusion");
    diffusion::check_compatible(s_.model->info(), s_.model->path(), "motion", "", {},
                                diffusion::posing_keypoint_ids(), diffusion::kKeypointsRepresentation);
  }

  void run(StageIO& io) override {
    const auto t0 = std::chrono::steady_clock::now();
    diffusion_plugin::check_encoder(*s_.model, io);
    const at::Tensor C = diffusion_plugin::contact_condition(*s_.model, s_.options, io, "motion.diffusion");
    const Guidance* guidance = nullptr;
    if (io.has("guidance")) guidance = io.in<std::shared_ptr<const Guidance>>("guidance").get();
    const ConstraintChain constraint = constraints(io);
    const at::Tensor X = s_.model->generate(io.in<at::Tensor>("object_features"), io.in<at::Tensor>("global_states"), C,
                                            guidance, s_.options, diffusion_plugin::stage_generator(io),
                                            constraint.empty() ? nullptr : &constraint);
    log::info("motion.diffusion: {} frames x {} samples in {:.2f} s", X.size(1), X.size(0),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    io.out("hand_keypoints", X[0].contiguous());
    io.out("hand_keypoints_samples", X);
  }

 private:
  // The pins and hands kept off of `hand_constraints`, then a kept sample's frames.
  ConstraintChain constraints(StageIO& io) const {
    ConstraintChain chain;
    if (!io.has("hand_constraints")) return chain;
    const HandConstraints& c = io.in<HandConstraints>("hand_constraints");
    const bool away = std::any_of(c.contacts.begin(), c.contacts.end(),
                                  [](const ContactConstraint& k) { return k.part == ContactPart::None; });
    if (c.pins.empty() && !away && !c.keep) return chain;
    if (!io.has("object") || !io.has("object_states") || !io.has("basis_hit_indices"))
      throw Error("motion.diffusion: hand_constraints need the object, object_states and basis_hit_indices wired");
    const auto& object = io.in<ArticulatedObject>("object");
    const auto& states = io.in<at::Tensor>("object_states");
    const std::array<HandModel, 2> hands =
        load_hand_models(mano_[0].empty() ? find_data_file("models/hand/mano_left.npz") : mano_[0],
                         mano_[1].empty() ? find_data_file("models/hand/mano_right.npz") : mano_[1]);
    const std::array<const HandModel*, 2> models{&hands[0], &hands[1]};
    if (!c.pins.empty() || away) {
      const at::Tensor points = basis_hit_points(object, states, io.in<at::Tensor>("basis_hit_indices"));
      chain.add(std::make_shared<HandPins>(c, models, states, points, pin_sigma_));
    }
    if (c.keep) chain.add(kept_hand_features(*c.keep, models, object, states));
    return chain;
  }

  diffusion_plugin::Sampling s_;
  double pin_sigma_ = 4.0;
  std::array<std::string, 2> mano_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::MotionDiffusion)
