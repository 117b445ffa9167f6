// Stage kind "encoder": turns the object and its 7-DoF trajectory into the conditions of
// both diffusion models (DESIGN §4): BPS features O, global states G and the scale s_o,
// plus the basis and the object vertex each basis point hits, which contact maps use.
// Implementations differ in the basis and what it is mapped to (U-BPS, NPA-BPS, NP-BPS);
// all of them use 1024 basis rows in total, so every model sees the same shapes.
#pragma once

#include <ATen/core/Tensor.h>

#include "core/object/articulated_object.h"
#include "core/pipeline/stage.h"

namespace bimart {

class ObjectEncoder : public Stage {
 public:
  static constexpr const char* kKind = "encoder";

  // Rows are "basis rows": k in [0, 1024). For NP-BPS rows 0..511 map the 512 basis points
  // to the top part and rows 512..1023 map the same points to the bottom part; U-BPS and
  // NPA-BPS map 1024 points to the whole object. "Encoder space" is the canonical frame
  // (root pose removed, hinge angle of the frame applied) scaled by s_o for NPA-BPS and
  // NP-BPS, and in metres for U-BPS.
  static void declare(StageSpec& s) {
    s.input<ArticulatedObject>("object", "the two-part object in its canonical frame, metres")
        .input<at::Tensor>("object_states",
                           "[N, 7] float32: per frame [angle, rx, ry, rz, tx, ty, tz] (rad, m)")
        .output<at::Tensor>(
            "object_features",
            "O: [N, 1024, 3] float32: per frame and basis row k, the vector from basis point k "
            "to the nearest object vertex (of the row's part for NP-BPS), in encoder space; "
            "NP-BPS rows 0..511 top, 512..1023 bottom")
        .output<at::Tensor>(
            "global_states",
            "G: [N, 7] float32: root axis-angle (rad), root translation (m) minus that of "
            "frame 0 of the sequence, s_o; generators working window by window subtract the "
            "window's first translation to get DESIGN §4's per-window G")
        .output<double>("object_scale",
                        "s_o = 0.85 / max ||v|| over both parts in the canonical frame (1/m)")
        .output<at::Tensor>(
            "basis_hit_indices",
            "[N, 1024] int64: per frame and basis row, the hit object vertex as an index into "
            "the concatenated vertex list [top; bottom]; varies with the hinge angle")
        .output<at::Tensor>(
            "basis_points",
            "[1024, 3] float32: the stored basis point of each row, in encoder space "
            "(NP-BPS: the 512 points twice); hit vertex = basis point + feature")
        .output<std::string>(
            "encoder_variant",
            "the BPS variant of O and of the basis rows: np_bps, npa_bps or u_bps (a model's "
            "`variant`); the diffusion stages refuse a model trained on another");
  }
};

}  // namespace bimart
