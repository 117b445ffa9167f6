// motion.diffusion_mano: the MANO-Rep motion model (the paper's Table 3 ablation row). It
// samples per hand the 6D rotations of the 16 MANO joints, the wrist position and the joint
// positions in the canonical frame (core/features/mano_representation.h), with contact
// conditioning and classifier-free guidance as motion.diffusion but no guidance strategy, and
// turns them into hands with the hand model: rotations and wrist, β = 0 (the model's mean
// shape), no keypoint fit. It writes what refine.mano_fit writes (hand_params, hand_samples,
// vertices posed), so the stages after a fit run unchanged, and the keypoints X of the
// decoded hands (the motion kind's output).
#include <fmt/format.h>

#include <chrono>

#include "core/diffusion/representation.h"
#include "core/features/hand_features.h"
#include "core/features/mano_representation.h"
#include "core/hand/keypoints.h"
#include "core/pipeline/plugin.h"
#include "core/refine/mano_fit.h"
#include "core/util/log.h"
#include "model_params.h"
#include "plugins/refine/hand_models.h"
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
        .input<ArticulatedObject>("object", "the two-part object in its canonical frame (for the keypoints' D)")
        .input<at::Tensor>("object_states", "[N, 7] float32: maps the canonical frame to the world frame")
        .optional_input<at::Tensor>("contact_maps_samples",
                                    "[S, N, 2, 1024]: one contact map per sample (contact.diffusion's samples)")
        .optional_input<std::string>("contact_model",
                                     "the contact model that sampled the maps; refused unless it was trained on "
                                     "the same encoder variant and with G as this model was, or both without")
        .output<at::Tensor>("hand_keypoints_samples", "[S, N, 1200] float32: X of every sample's decoded hands")
        .output<HandMotion>("hand_params",
                            "sample 0: N frames, world frame, ARCTIC layout, β = 0, posed vertices [2, N, V, 3]")
        .output<std::vector<HandMotion>>("hand_samples", "every sample (S motions like hand_params)");
    refine_plugin::declare_hand_params(s);
    return s;
  }

  explicit MotionDiffusionMano(const Params& p)
      : s_(diffusion_plugin::read_sampling_params(p)), hands_(refine_plugin::load_hand_pair(p)) {
    s_.options.cfg_lambda = p.number("cfg");
    s_.options.use_contact = p.boolean("use_contact");
    const diffusion::ModelInfo& info = s_.model->info();
    if (info.network.model != "motion")
      throw Error(s_.model->path() + " is a " + info.network.model + " model, not a motion model");
    if (info.representation != diffusion::kManoRepresentation)
      throw Error("motion.diffusion_mano samples the MANO representation (MANO-Rep), but " + s_.model->path() +
                  " samples " + diffusion::describe_representation(info.representation) +
                  ": use motion.diffusion for it");
    diffusion::check_compatible(info, s_.model->path(), "motion", "", {}, {}, diffusion::kManoRepresentation);
    keypoint_ids_ = model_keypoints(hands_->models[0]);
    if (model_keypoints(hands_->models[1]) != keypoint_ids_)
      throw Error("mano_left and mano_right have different keypoint ids; the keypoints X need the same on both sides");
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
    const at::Tensor& states = io.in<at::Tensor>("object_states");
    const ArticulatedObject& object = io.in<ArticulatedObject>("object");
    if (states.dim() != 2 || states.size(0) != M.size(1))
      throw Error("motion.diffusion_mano: object_states has " + std::to_string(states.dim() == 2 ? states.size(0) : -1) +
                  " frames, the object features " + std::to_string(M.size(1)));
    const auto models = hands_->pointers();
    const std::array<at::Tensor, 2> shapes{at::zeros({HandModel::kNumBetas}), at::zeros({HandModel::kNumBetas})};
    std::vector<HandMotion> hands;
    std::vector<at::Tensor> keypoints;
    for (std::int64_t k = 0; k < M.size(0); ++k) {
      HandMotion h = hands_from_mano_representation(models, M[k], states, shapes);
      h.vertices = pose_hand_vertices(models, h);
      keypoints.push_back(hand_features(h.vertices, keypoint_ids_, object, states));
      hands.push_back(std::move(h));
    }
    log::info("motion.diffusion_mano: {} frames x {} samples in {:.2f} s", M.size(1), M.size(0),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    const at::Tensor X = at::stack(keypoints);
    io.out("hand_keypoints", X[0].contiguous());
    io.out("hand_keypoints_samples", X);
    io.out("hand_params", hands[0]);
    io.out("hand_samples", std::move(hands));
  }

 private:
  diffusion_plugin::Sampling s_;
  std::shared_ptr<const refine_plugin::HandPair> hands_;
  std::vector<int> keypoint_ids_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::MotionDiffusionMano)
