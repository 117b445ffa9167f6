// Stage kind "trajectory": where a run starts. Produces the articulated object and its
// 7-DoF trajectory.
#pragma once

#include <ATen/core/Tensor.h>

#include "core/object/articulated_object.h"
#include "core/pipeline/stage.h"

namespace bimart {

class TrajectorySource : public Stage {
 public:
  static constexpr const char* kKind = "trajectory";

  static void declare(StageSpec& s) {
    s.output<ArticulatedObject>(
         "object", "the two-part object in its canonical frame (hinge: -z through the origin), metres")
        .output<at::Tensor>(
            "object_states",
            "[N, 7] float32: per frame [angle, rx, ry, rz, tx, ty, tz] (ARCTIC order): hinge angle "
            "(rad), root axis-angle (rad), root translation (m)")
        .output<double>("fps", "frames per second of object_states");
  }
};

}  // namespace bimart
