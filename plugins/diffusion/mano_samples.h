// What every stage that makes MANO hands itself writes (motion.diffusion_mano, and the
// baselines' motion.mdm_b, motion.omomo_b and motion.cams_b): the hands, as refine.mano_fit
// writes them, so every stage after a fit runs unchanged, and the keypoints X of the hands.
// MANO-Rep samples [S, N, 294] are turned into hands by the hand model (rotations and wrist,
// β = 0, no keypoint fit).
#pragma once

#include <array>
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "core/features/hand_features.h"
#include "core/features/mano_representation.h"
#include "core/hand/keypoints.h"
#include "core/pipeline/stage.h"
#include "core/refine/mano_fit.h"
#include "core/util/log.h"
#include "plugins/refine/hand_models.h"

namespace bimart::diffusion_plugin {

// The inputs the decoding needs and the outputs it writes, and the hand model parameters.
inline void declare_mano_hands(StageSpec& s) {
  s.input<ArticulatedObject>("object", "the two-part object in its canonical frame (for the keypoints' D)")
      .input<at::Tensor>("object_states", "[N, 7] float32: maps the canonical frame to the world frame")
      .output<at::Tensor>("hand_keypoints_samples", "[S, N, 1200] float32: X of every sample's decoded hands")
      .output<HandMotion>("hand_params",
                          "sample 0: N frames, world frame, ARCTIC layout, β = 0, posed vertices [2, N, V, 3]")
      .output<std::vector<HandMotion>>("hand_samples", "every sample (S motions like hand_params)");
  refine_plugin::declare_hand_params(s);
}

class ManoHands {
 public:
  explicit ManoHands(const Params& p) : hands_(refine_plugin::load_hand_pair(p)) {
    ids_ = model_keypoints(hands_->models[0]);
    if (model_keypoints(hands_->models[1]) != ids_)
      throw Error("mano_left and mano_right have different keypoint ids; the keypoints X need the same on both sides");
  }

  const refine_plugin::HandPair& hands() const { return *hands_; }

  // M [S, N, 294] (canonical frame) -> the stage's outputs; `stage` and `t0` for the log.
  void write(StageIO& io, const at::Tensor& M, const std::string& stage,
             std::chrono::steady_clock::time_point t0) const {
    const at::Tensor& states = io.in<at::Tensor>("object_states");
    if (states.dim() != 2 || states.size(0) != M.size(1))
      throw Error(stage + ": object_states has " + std::to_string(states.dim() == 2 ? states.size(0) : -1) +
                  " frames, the samples " + std::to_string(M.size(1)));
    const auto models = hands_->pointers();
    const std::array<at::Tensor, 2> shapes{at::zeros({HandModel::kNumBetas}), at::zeros({HandModel::kNumBetas})};
    std::vector<HandMotion> hands;
    for (std::int64_t k = 0; k < M.size(0); ++k) hands.push_back(hands_from_mano_representation(models, M[k], states, shapes));
    write_hands(io, std::move(hands));
    log::info("{}: {} frames x {} samples in {:.2f} s", stage, M.size(1), M.size(0),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }

  // Hands in the world frame, one motion per sample -> posed vertices, X and the outputs.
  void write_hands(StageIO& io, std::vector<HandMotion> hands) const {
    const at::Tensor& states = io.in<at::Tensor>("object_states");
    const ArticulatedObject& object = io.in<ArticulatedObject>("object");
    const auto models = hands_->pointers();
    std::vector<at::Tensor> keypoints;
    for (HandMotion& h : hands) {
      h.vertices = pose_hand_vertices(models, h);
      keypoints.push_back(hand_features(h.vertices, ids_, object, states));
    }
    const at::Tensor X = at::stack(keypoints);
    io.out("hand_keypoints", X[0].contiguous());
    io.out("hand_keypoints_samples", X);
    io.out("hand_params", hands[0]);
    io.out("hand_samples", std::move(hands));
  }

 private:
  std::shared_ptr<const refine_plugin::HandPair> hands_;
  std::vector<int> ids_;
};

}  // namespace bimart::diffusion_plugin
