#include "core/metrics/contact_map_error.h"

#include <ATen/ATen.h>

#include "core/features/contact_map.h"
#include "core/object/object_state.h"
#include "core/util/error.h"

namespace bimart {

double contact_map_error(const ArticulatedObject& object, const at::Tensor& states_in,
                         const at::Tensor& hit_indices, const at::Tensor& keypoints_world,
                         const at::Tensor& conditioning) {
  at::NoGradGuard no_grad;
  const at::Tensor states = states_in.to(at::kCPU, at::kDouble).contiguous();
  const int64_t n = states.size(0);
  if (keypoints_world.dim() != 4 || keypoints_world.size(0) != 2 || keypoints_world.size(1) != n)
    throw Error("CM: keypoints must be [2, N, J, 3] with N = the object's frames");
  if (conditioning.dim() != 3 || conditioning.size(0) != n || conditioning.size(1) != 2)
    throw Error("CM: the conditioning contact maps must be [N, 2, 1024]");
  // Keypoints into the canonical frame (root pose removed): basis hit points live there.
  at::Tensor kp = keypoints_world.to(at::kCPU, at::kDouble).clone();
  const double* s = states.data_ptr<double>();
  for (int64_t t = 0; t < n; ++t) {
    const Eigen::Isometry3d w2c = canonical_to_world(ObjectState::from_row(s + 7 * t)).inverse();
    const Eigen::Matrix4d m = w2c.matrix();
    const at::Tensor r = at::from_blob(const_cast<double*>(m.data()), {4, 4}, at::kDouble).t().clone();
    for (int h = 0; h < 2; ++h) {
      at::Tensor p = kp[h][t];  // [J, 3]
      p.copy_(at::matmul(p, r.slice(0, 0, 3).slice(1, 0, 3).t()) + r.slice(0, 0, 3).select(1, 3));
    }
  }
  const at::Tensor points = basis_hit_points(object, states_in, hit_indices).to(at::kDouble);
  const at::Tensor generated = contact_maps(points, kp);  // [N, 2, 1024]
  if (!generated.sizes().equals(conditioning.sizes()))
    throw Error("CM: the conditioning contact maps do not match the basis (1024 rows)");
  return (generated - conditioning.to(at::kDouble)).abs().mean().item<double>();
}

}  // namespace bimart
