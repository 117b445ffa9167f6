// OMOMO-B's contact constraint (docs/baselines.md): at every denoising step, each joint of
// either hand that comes within `reach` of the object is put on the object's surface, as
// OMOMO (Li et al. 2023) puts its predicted wrists on the object where they come near it.
// The surface is the object's mesh vertices posed at each frame's hinge angle (canonical
// frame); the nearest vertex stands for the nearest surface point, which the meshes' vertex
// spacing (a few millimetres) allows.
#pragma once

#include <cstdint>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/geometry/nearest_points.h"
#include "core/object/articulated_object.h"
#include "stages/sample_constraint.h"

namespace bimart {

class JointContact : public SampleConstraint {
 public:
  // states [N, 7]: the run's object states (the hinge angle of each frame).
  JointContact(const ArticulatedObject& object, const at::Tensor& states, double reach);

  // x0 [B, T, 96]: both hands' joints (m, canonical frame) of frames [first, first + T).
  at::Tensor impose(const at::Tensor& x0, std::int64_t first, int step, int num_steps) const override;

 private:
  std::vector<NearestPoints> surfaces_;  // per frame
  double reach_;
};

}  // namespace bimart
