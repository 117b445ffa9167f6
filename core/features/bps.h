// Basis point sets (BPS) for the object: the basis, and the three encoders of the paper's
// ablation (DESIGN §4, stages/object_encoder.h for the output contract).
#pragma once

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <string>

#include "core/geometry/nearest_points.h"
#include "core/object/articulated_object.h"
#include "core/object/object_state.h"

namespace bimart {

// Points uniform in a ball, made once from a seed and stored; loaded, never regenerated.
struct BpsBasis {
  Points3 points;        // [K, 3]
  double radius = 1.0;   // of the ball they were drawn in
  std::uint64_t seed = 0;
};

// K points uniform in the ball of `radius` (rejection sampling from the cube with
// mt19937_64 and our own [0,1) mapping, so the points are the same on every platform).
BpsBasis make_bps_basis(int count, double radius, std::uint64_t seed);
// .npz with keys points [K,3] f8, radius f8, seed u8.
BpsBasis load_bps_basis(const std::string& path);
void save_bps_basis(const BpsBasis& basis, const std::string& path);

enum class BpsVariant {
  Uniform,        // U-BPS: 1024 points in a 0.5 m ball, object in metres, parts ignored
  PartAgnostic,   // NPA-BPS: 1024 points in the unit ball, object scaled by s_o, parts ignored
  PerPart,        // NP-BPS: 512 points in the unit ball mapped to each part, scaled by s_o
};

// The shipped basis file of a variant, relative to the data folder (core/util/data_path.h).
const char* default_basis_file(BpsVariant variant);
// The number of basis points a variant's basis must have (512 or 1024).
int basis_size(BpsVariant variant);

struct ObjectEncoding {
  at::Tensor features;       // [N, 1024, 3] float32
  at::Tensor hit_indices;    // [N, 1024] int64 into [top; bottom]
  at::Tensor global_states;  // [N, 7] float32
  at::Tensor basis_points;   // [1024, 3] float32
  double scale = 1.0;        // s_o
};

// Encodes every frame of `states` ([N, 7]). Each part's k-d tree is built once in the
// part's own frame; per frame the basis is moved into the top part's frame instead.
ObjectEncoding encode_object(const ArticulatedObject& object, const at::Tensor& states,
                             const BpsBasis& basis, BpsVariant variant);

}  // namespace bimart
