#include "core/features/bps.h"

#include <ATen/ATen.h>
#include <Eigen/Geometry>

#include <cmath>
#include <random>

#include "core/io/npz.h"
#include "core/util/error.h"

namespace bimart {

ObjectEncoding encode_object(const ArticulatedObject& object, const at::Tensor& states,
                             const BpsBasis& basis, BpsVariant variant) {
  if (states.dim() != 2 || states.size(1) != 7)
    throw Error("object_states must be [N, 7], got " + std::string(c10::str(states.sizes())));
  const int k = basis_size(variant);
  if (basis.points.rows() != k)
    throw Error("the basis has " + std::to_string(basis.points.rows()) + " points; this encoder needs " +
                std::to_string(k));
  if (object.top.num_vertices() == 0 || object.bottom.num_vertices() == 0)
    throw Error("object '" + object.name + "' has an empty part");

  const double s_o = object_scale(object);
  const double s = variant == BpsVariant::Uniform ? 1.0 : s_o;
  const NearestPoints top(s * object.top.vertices);
  const NearestPoints bottom(s * object.bottom.vertices);
  const int vt = static_cast<int>(object.top.num_vertices());

  const at::Tensor st = states.to(at::kDouble).contiguous();
  const auto S = st.accessor<double, 2>();
  const int64_t n = st.size(0);
  for (int64_t t = 0; t < n; ++t)
    for (int c = 0; c < 7; ++c)
      if (!std::isfinite(S[t][c]))
        throw Error("object_states frame " + std::to_string(t) + " holds a non-finite number");

  ObjectEncoding out;
  out.scale = s_o;
  out.features = at::empty({n, 1024, 3}, at::kFloat);
  out.hit_indices = at::empty({n, 1024}, at::kLong);
  out.global_states = at::empty({n, 7}, at::kFloat);
  out.basis_points = at::empty({1024, 3}, at::kFloat);
  auto F = out.features.accessor<float, 3>();
  auto H = out.hit_indices.accessor<int64_t, 2>();
  auto G = out.global_states.accessor<float, 2>();
  auto B = out.basis_points.accessor<float, 2>();
  for (int row = 0; row < 1024; ++row)
    for (int c = 0; c < 3; ++c) B[row][c] = static_cast<float>(basis.points(row % k, c));

  // Bottom hits do not depend on the frame: the bottom part is fixed in the canonical frame.
  std::vector<int> bottom_idx(k), top_idx(k);
  std::vector<double> bottom_d2(k), top_d2(k);
  bottom.nearest(basis.points, bottom_idx.data(), bottom_d2.data());

  const bool per_part = variant == BpsVariant::PerPart;
  Points3 moved(k, 3);
  for (int64_t t = 0; t < n; ++t) {
    const double angle = S[t][0];
    if (t > 0 && angle == S[t - 1][0]) {  // same articulation: same rows
      out.features[t].copy_(out.features[t - 1]);
      out.hit_indices[t].copy_(out.hit_indices[t - 1]);
    } else {
      const Eigen::Matrix3d R = top_to_canonical(angle).linear();
      moved = basis.points * R;  // rows R^T b: the basis in the top part's own frame
      top.nearest(moved, top_idx.data(), top_d2.data());
      auto write = [&](int row, int basis_index, const Eigen::Vector3d& hit, int64_t vertex) {
        const Eigen::Vector3d v = hit - basis.points.row(basis_index).transpose();
        for (int c = 0; c < 3; ++c) F[t][row][c] = static_cast<float>(v[c]);
        H[t][row] = vertex;
      };
      for (int i = 0; i < k; ++i) {
        const Eigen::Vector3d top_hit = R * top.points().row(top_idx[i]).transpose();
        const Eigen::Vector3d bottom_hit = bottom.points().row(bottom_idx[i]).transpose();
        if (per_part) {
          write(i, i, top_hit, top_idx[i]);
          write(k + i, i, bottom_hit, vt + bottom_idx[i]);
        } else if (top_d2[i] <= bottom_d2[i]) {
          write(i, i, top_hit, top_idx[i]);
        } else {
          write(i, i, bottom_hit, vt + bottom_idx[i]);
        }
      }
    }
    for (int c = 0; c < 3; ++c) {
      G[t][c] = static_cast<float>(S[t][1 + c]);
      G[t][3 + c] = static_cast<float>(S[t][4 + c] - S[0][4 + c]);
    }
    G[t][6] = static_cast<float>(s_o);
  }
  return out;
}

}  // namespace bimart
