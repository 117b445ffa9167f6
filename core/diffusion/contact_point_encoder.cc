#include "core/diffusion/contact_point_encoder.h"

#include <ATen/ATen.h>
#include <torch/nn/modules/activation.h>

#include <string>

#include "core/util/error.h"

namespace bimart::diffusion {

ContactPointEncoderImpl::ContactPointEncoderImpl(int k, int hidden, int out) : k_(k) {
  point_mlp_ = register_module("point_mlp", torch::nn::Sequential(torch::nn::Linear(7, hidden), torch::nn::ReLU(),
                                                                  torch::nn::Linear(hidden, hidden), torch::nn::ReLU()));
  out_ = register_module("out", torch::nn::Linear(4 * hidden, out));
}

at::Tensor ContactPointEncoderImpl::forward(const at::Tensor& points, const at::Tensor& offsets,
                                            const at::Tensor& contact_maps) {
  if (points.dim() != 4 || points.size(-1) != 3 || !offsets.sizes().equals(points.sizes()) ||
      contact_maps.dim() != 4 || contact_maps.size(2) != 2 || contact_maps.size(3) != points.size(2) ||
      contact_maps.size(0) != points.size(0) || contact_maps.size(1) != points.size(1) || points.size(2) < k_)
    throw Error("contact point encoder: need points and offsets [B, T, N >= " + std::to_string(k_) +
                ", 3] and contact maps [B, T, 2, N], got " + std::string(c10::str(points.sizes())) + ", " +
                std::string(c10::str(offsets.sizes())) + " and " + std::string(c10::str(contact_maps.sizes())));
  const auto B = points.size(0), T = points.size(1), N = points.size(2);
  const at::Tensor d = contact_maps / 0.1;                                             // dm
  const auto [nearest, index] = at::topk(d, k_, -1, /*largest=*/false, /*sorted=*/false);  // [B, T, 2, K]
  const at::Tensor per_point = at::cat({points / 0.1, offsets}, -1);                  // [B, T, N, 6]
  const at::Tensor picked = per_point.unsqueeze(2).expand({B, T, 2, N, 6})
                                .gather(3, index.unsqueeze(-1).expand({B, T, 2, k_, 6}));  // [B, T, 2, K, 6]
  const at::Tensor features = point_mlp_->forward(
      at::cat({picked.slice(-1, 0, 3), nearest.unsqueeze(-1), picked.slice(-1, 3, 6)}, -1));  // [B, T, 2, K, h]
  const at::Tensor pooled = at::cat({std::get<0>(features.max(3)), features.mean(3)}, -1);  // [B, T, 2, 2h]
  return out_->forward(pooled.flatten(2));
}

}  // namespace bimart::diffusion
