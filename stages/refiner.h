// Stage kind "refine": turns the generated keypoints X into MANO-layout hand motion in the
// world frame (DESIGN §2, §5): fit MANO to the keypoints, then refine against projection,
// penetration and acceleration terms. Refiners chain: one may start from an earlier one's
// `hand_params` (e.g. refine.mano_fit, then refine.ceres).
#pragma once

#include <ATen/core/Tensor.h>

#include "core/hand/hand_motion.h"
#include "core/object/articulated_object.h"
#include "core/pipeline/stage.h"

namespace bimart {

class Refiner : public Stage {
 public:
  static constexpr const char* kKind = "refine";

  static void declare(StageSpec& s) {
    s.input<at::Tensor>(
         "hand_keypoints",
         "X: [N, 1200] float32, metres, canonical object frame: [H_left, H_right, D_left, "
         "D_right], 300 each")
        .input<ArticulatedObject>("object", "the two-part object in its canonical frame, metres")
        .input<at::Tensor>("object_states",
                           "[N, 7] float32: per frame [angle, rx, ry, rz, tx, ty, tz] (rad, m); "
                           "maps the canonical frame to the world frame")
        .optional_input<HandMotion>("hand_params",
                                    "N frames, world frame: a previous refiner's result to start from")
        .output<HandMotion>(
            "hand_params",
            "N frames, world frame, ARCTIC layout (per hand rot [N,3], pose [N,45], trans "
            "[N,3], shape [10]), with posed vertices [2, N, V, 3] filled in");
  }
};

}  // namespace bimart
