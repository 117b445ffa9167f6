// Motion of both hands as MANO-layout parameters in the ARCTIC field layout (DESIGN §4,
// §7), in the world frame. Refiners produce it; exporters and metrics read it. Minimal on
// purpose: fields are added as later stages need them.
#pragma once

#include <array>
#include <cstdint>

#include <ATen/core/Tensor.h>

namespace bimart {

// One hand over N frames. All tensors float32, CPU.
struct HandParams {
  // [N, 3] global rotation, axis-angle (rad), world frame, about the hand's root joint.
  at::Tensor rot;
  // [N, 45] finger pose: 15 joints (index, middle, pinky, ring, thumb; 3 each, from the
  // palm out) × axis-angle (rad) relative to the parent joint. Zero is the flat hand
  // (converters from ARCTIC add MANO's mean pose first).
  at::Tensor pose;
  // [N, 3] translation (m), world frame, added after posing (MANO `transl`).
  at::Tensor trans;
  // [10] shape coefficients β, one set for the whole sequence.
  at::Tensor shape;
};

struct HandMotion {
  std::array<HandParams, 2> hands;  // 0 = left, 1 = right

  // Optional posed hand meshes: [2, N, V, 3] float32, metres, world frame, V = the hand
  // model's vertex count (778 in MANO layout). Undefined when not computed.
  at::Tensor vertices;

  std::int64_t num_frames() const { return hands[0].rot.defined() ? hands[0].rot.size(0) : 0; }
  bool has_vertices() const { return vertices.defined(); }
};

}  // namespace bimart
