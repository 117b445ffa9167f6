#include "core/features/contact_cue.h"

#include <ATen/ATen.h>

#include <cmath>
#include <string>

#include "core/features/bps.h"
#include "core/util/error.h"

namespace bimart {

at::Tensor contact_cue(const at::Tensor& points, const at::Tensor& contact_maps) {
  const auto rows = points.dim() >= 2 ? points.size(-2) : 0;
  if (points.dim() < 2 || points.size(-1) != 3 || contact_maps.dim() != points.dim() ||
      contact_maps.size(-2) != 2 || contact_maps.size(-1) != rows ||
      !points.sizes().slice(0, points.dim() - 2).equals(contact_maps.sizes().slice(0, contact_maps.dim() - 2)))
    throw Error("contact cue: need points [..., K, 3] and contact maps [..., 2, K], got " +
                std::string(c10::str(points.sizes())) + " and " + std::string(c10::str(contact_maps.sizes())));
  const at::Tensor p = points.to(at::kFloat) / 0.1;        // [..., K, 3] dm
  const at::Tensor d = contact_maps.to(at::kFloat) / 0.1;  // [..., 2, K] dm
  const at::Tensor x = p.select(-1, 0), y = p.select(-1, 1), z = p.select(-1, 2);
  const at::Tensor moments = at::stack({x, y, z, x * x, y * y, z * z, x * y, x * z, y * z}, -1);  // [..., K, 9]
  std::vector<at::Tensor> parts;
  for (const double sigma : {0.1, 0.3, 1.0}) {  // dm
    const at::Tensor w = at::softmax(-d / sigma, -1);  // [..., 2, K]
    const at::Tensor m = at::matmul(w, moments);       // [..., 2, 9]
    const at::Tensor mu = m.slice(-1, 0, 3);
    const at::Tensor mx = mu.select(-1, 0), my = mu.select(-1, 1), mz = mu.select(-1, 2);
    const at::Tensor cov = m.slice(-1, 3, 9) - at::stack({mx * mx, my * my, mz * mz, mx * my, mx * mz, my * mz}, -1);
    const at::Tensor count = -w.pow(2).sum(-1, true).log() / 3.0;  // log of the effective count
    parts.insert(parts.end(), {mu, cov, count});
  }
  parts.push_back(std::get<0>(d.min(-1, true)));
  return at::cat(parts, -1).flatten(-2);  // [..., 2 · 31]
}

at::Tensor object_points_from_bps(const at::Tensor& object_features, const at::Tensor& basis_points,
                                  const at::Tensor& scale) {
  if (object_features.dim() < 2 || object_features.size(-1) != 3 || !basis_points.sizes().equals(object_features.sizes().slice(object_features.dim() - 2)))
    throw Error("object points: need BPS features [..., K, 3] and basis points [K, 3], got " +
                std::string(c10::str(object_features.sizes())) + " and " + std::string(c10::str(basis_points.sizes())));
  const at::Tensor s = scale.dim() == 0 ? scale : scale.unsqueeze(-1).unsqueeze(-1);
  return (object_features + basis_points) / s;
}

at::Tensor object_points_from_bps(const at::Tensor& object_features, const at::Tensor& basis_points,
                                  const at::Tensor& object_scale, BpsVariant variant) {
  return object_points_from_bps(object_features, basis_points,
                                variant == BpsVariant::Uniform ? at::ones_like(object_scale) : object_scale);
}

}  // namespace bimart
