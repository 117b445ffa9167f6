// Batched, differentiable linear blend skinning on tensors: the same MANO convention as
// lbs.h (see there), for B hands at once (B = frames × hands, flattened by the caller).
// Gradients flow to rot, pose, trans and betas through autograd.
#pragma once

#include <array>
#include <cstdint>

#include <ATen/core/Tensor.h>

#include "core/hand/hand_model.h"

namespace bimart {

// A hand model as CPU tensors of one floating type, laid out for batched products.
// "Coordinate-major" vectors of 3V entries hold all x, then all y, then all z (index k·V + v):
// the layout that keeps every per-vertex operation a contiguous run over V.
struct HandModelTensors {
  at::Tensor v_template;        // [V, 3]
  at::Tensor v_template_cm;     // [3V] coordinate-major
  at::Tensor blend_dirs;        // [145, 3V] coordinate-major: 10 shape rows, then 135 pose rows
  at::Tensor j_template;        // [16, 3] = J_regressor · v_template
  at::Tensor j_shapedirs;       // [10, 48]: rest joints move linearly with β
  at::Tensor weights_t;         // [16, V]: skinning weights, transposed
  at::Tensor fingertips;        // [5] int64: thumb, index, middle, ring, pinky
  at::Tensor hands_mean;        // [45]
  at::Tensor hands_components;  // [45, 45], one component per row
  std::array<int, 16> parents{};

  // dtype: at::kFloat or at::kDouble.
  static HandModelTensors from(const HandModel& model, at::ScalarType dtype = at::kFloat);
  at::ScalarType dtype() const { return v_template.scalar_type(); }
  int64_t num_vertices() const { return v_template.size(0); }
};

struct LbsTensors {
  at::Tensor vertices;  // [B, V, 3] metres
  at::Tensor joints;    // [B, 16, 3] metres
};

// rot [B,3] global axis-angle, pose [B,45] flat finger axis-angle, trans [B,3], betas [B,10],
// all of the model's dtype. Throws bimart::Error on a wrong shape or dtype.
LbsTensors lbs(const HandModelTensors& model, const at::Tensor& rot, const at::Tensor& pose,
               const at::Tensor& trans, const at::Tensor& betas);

// [B, 21, 3]: the 16 joints, then the fingertip vertices (thumb, index, middle, ring, pinky).
at::Tensor keypoints21(const HandModelTensors& model, const LbsTensors& posed);

// Axis-angle [..., 3] to rotation matrices [..., 3, 3]; exact at zero with finite gradients.
at::Tensor axis_angle_to_matrix(const at::Tensor& aa);

}  // namespace bimart
