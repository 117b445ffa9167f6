// Stage kind "motion": generates the hand representation X = [H | D] of both hands in the
// object's canonical frame (DESIGN §2, §4), conditioned on the object features and,
// optionally, on contact maps (classifier-free guidance) and a guidance strategy applied
// at every diffusion step. Long sequences are generated window by window.
#pragma once

#include <memory>

#include <ATen/core/Tensor.h>

#include "core/pipeline/stage.h"
#include "stages/guidance.h"

namespace bimart {

class MotionGenerator : public Stage {
 public:
  static constexpr const char* kKind = "motion";

  static void declare(StageSpec& s) {
    s.input<at::Tensor>("object_features", "O: [N, 1024, 3] float32, from an encoder")
        .input<at::Tensor>("global_states", "G: [N, 7] float32, from an encoder")
        .input<double>("object_scale", "s_o (1/m), from an encoder")
        .optional_input<at::Tensor>(
            "contact_maps",
            "C: [N, 2, 1024] float32, metres; when absent the null contact token is used")
        .optional_input<std::shared_ptr<const Guidance>>(
            "guidance", "applied to the predicted clean sample at every diffusion step")
        .optional_input<at::Tensor>(
            "basis_points",
            "[1024, 3] float32; when wired, checked against the basis stored with the model")
        .optional_input<std::string>(
            "encoder_variant",
            "the encoder's BPS variant (np_bps, npa_bps, u_bps); when wired, a model trained on "
            "another is refused")
        .output<at::Tensor>(
            "hand_keypoints",
            "X: [N, 1200] float32, metres, canonical object frame: [H_left(300), "
            "H_right(300), D_left(300), D_right(300)]; H = 100 keypoints × xyz, D = per "
            "keypoint the vector to its nearest object vertex");
  }
};

}  // namespace bimart
