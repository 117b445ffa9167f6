// Stage kind "joints" (a plug-in's own kind, as a third party may define one): generates
// the joint positions of both hands in the object's canonical frame from the object
// features — OMOMO-B's first stage (docs/baselines.md). A "motion." stage conditioned on
// the joints turns them into hands.
#pragma once

#include <ATen/core/Tensor.h>

#include "core/pipeline/stage.h"

namespace bimart {

class JointsGenerator : public Stage {
 public:
  static constexpr const char* kKind = "joints";

  static void declare(StageSpec& s) {
    s.input<at::Tensor>("object_features", "O: [N, 1024, 3] float32, from an encoder")
        .input<at::Tensor>("global_states", "G: [N, 7] float32, from an encoder")
        .optional_input<at::Tensor>("basis_points", "[1024, 3] float32; checked against the model's basis")
        .optional_input<std::string>("encoder_variant", "the encoder's BPS variant; a model of another is refused")
        .output<at::Tensor>("hand_joints",
                            "[N, 96] float32, metres, canonical object frame: the 16 MANO joints of the left "
                            "hand, then of the right (x, y, z each), sample 0")
        .output<at::Tensor>("hand_joints_samples", "[S, N, 96]: every sample");
  }
};

}  // namespace bimart
