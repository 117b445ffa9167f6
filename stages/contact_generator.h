// Stage kind "contact": generates the bimanual contact maps C from the object conditions
// (DESIGN §2, §4). C is the intermediate target that conditions and guides the motion
// generator; it needs no reference grasp. Output entries follow the encoder's basis rows.
#pragma once

#include <ATen/core/Tensor.h>

#include "core/pipeline/stage.h"

namespace bimart {

class ContactGenerator : public Stage {
 public:
  static constexpr const char* kKind = "contact";

  static void declare(StageSpec& s) {
    s.input<at::Tensor>("object_features", "O: [N, 1024, 3] float32, from an encoder")
        .input<at::Tensor>("global_states", "G: [N, 7] float32, from an encoder")
        .input<double>("object_scale", "s_o (1/m), from an encoder")
        .optional_input<at::Tensor>(
            "basis_points",
            "[1024, 3] float32; when wired, checked against the basis stored with the model")
        .optional_input<std::string>(
            "encoder_variant",
            "the encoder's BPS variant (np_bps, npa_bps, u_bps); when wired, a model trained on "
            "another is refused")
        .output<at::Tensor>(
            "contact_maps",
            "C: [N, 2, 1024] float32, metres (not scaled by s_o): per frame, hand (0 = left, "
            "1 = right) and basis row, the distance from the row's hit object vertex to the "
            "nearest vertex of that hand");
  }
};

}  // namespace bimart
