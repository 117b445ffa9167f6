// The contact point encoder (experimental, `network.contact_points`): a PointNet over the
// object points each hand is closest to. For every frame and hand it takes the K object
// points with the smallest contact-map distance, reads per point [position (dm), distance
// (dm), BPS offset (encoder space)] with a shared two-layer MLP, and pools max and mean
// over the K points; both hands' pools go through one linear layer to a frame token.
// Unlike an MLP over the 2048 distances, it pairs each distance with the point it belongs
// to, and max-pooling keeps the footprint's asymmetry (which way the fingers point) that
// the contact cue's mean and covariance lose (docs/training.md, "Contact points").
#pragma once

#include <ATen/core/Tensor.h>
#include <torch/nn/module.h>
#include <torch/nn/modules/container/sequential.h>
#include <torch/nn/modules/linear.h>

namespace bimart::diffusion {

class ContactPointEncoderImpl : public torch::nn::Module {
 public:
  // k: points per hand and frame (≤ 1024); hidden: width of the point MLP; out: token width.
  ContactPointEncoderImpl(int k, int hidden, int out);
  // points [B, T, N, 3] (metres, canonical frame), offsets [B, T, N, 3] (the BPS features),
  // contact maps [B, T, 2, N] (metres) -> [B, T, out].
  at::Tensor forward(const at::Tensor& points, const at::Tensor& offsets, const at::Tensor& contact_maps);

 private:
  int k_;
  torch::nn::Sequential point_mlp_{nullptr};
  torch::nn::Linear out_{nullptr};
};
TORCH_MODULE(ContactPointEncoder);

}  // namespace bimart::diffusion
