// Stage kind "refine": turns the generated keypoints X into MANO-layout hand motion in the
// world frame (DESIGN §2, §5): fit MANO to the keypoints, then refine against projection,
// penetration and acceleration terms. Refiners chain: one may start from an earlier one's
// `hand_params` (e.g. refine.mano_fit, then refine.ceres).
//
// Several samples: when `hand_keypoints_samples` [S, N, 1200] is wired (a generator's
// batch), a refiner refines every sample, in parallel over the samples, and writes them to
// `hand_samples` (S motions, sample k from keypoints k, started from the k-th entry of an
// earlier refiner's `hand_samples` when wired); `hand_params` is then sample 0, and
// `hand_keypoints` must be sample 0 of the batch. Without the batch `hand_samples` holds
// the one result. Shared code: plugins/refine/samples.h.
#pragma once

#include <vector>

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
        .optional_input<at::Tensor>("hand_keypoints_samples",
                                    "[S, N, 1200] float32: every sample of the generator (S >= 1); "
                                    "each is refined")
        .optional_input<std::vector<HandMotion>>("hand_samples",
                                                 "S motions from a previous refiner, one per sample, to start from")
        .output<HandMotion>(
            "hand_params",
            "N frames, world frame, ARCTIC layout (per hand rot [N,3], pose [N,45], trans "
            "[N,3], shape [10]), with posed vertices [2, N, V, 3] filled in; sample 0")
        .output<std::vector<HandMotion>>("hand_samples",
                                         "every sample refined (S motions like hand_params; S = 1 without "
                                         "hand_keypoints_samples)");
  }
};

}  // namespace bimart
