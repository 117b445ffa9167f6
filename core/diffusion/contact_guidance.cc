#include "core/diffusion/contact_guidance.h"

#include <ATen/ATen.h>

#include "core/features/hand_features.h"
#include "core/util/error.h"

namespace bimart::diffusion {

ContactMapGuidance::ContactMapGuidance(at::Tensor object_points, at::Tensor target, double scale)
    : points_(object_points.to(at::kFloat).contiguous()), scale_(scale) {
  if (points_.dim() != 3 || points_.size(1) != 1024 || points_.size(2) != 3)
    throw Error("contact-map guidance: object points must be [N, 1024, 3], got " + c10::str(points_.sizes()));
  target_ = target.to(at::kFloat);
  if (target_.dim() == 3) target_ = target_.unsqueeze(0);
  if (target_.dim() != 4 || target_.size(1) != points_.size(0) || target_.size(2) != 2 || target_.size(3) != 1024)
    throw Error("contact-map guidance: contact maps must be [N, 2, 1024] or [S, N, 2, 1024] with N = " +
                std::to_string(points_.size(0)) + ", got " + c10::str(target.sizes()));
  target_ = target_.contiguous();
  if (!(scale >= 0)) throw Error("contact-map guidance: scale must not be negative");
}

std::pair<at::Tensor, at::Tensor> ContactMapGuidance::keypoint_contact_map(const at::Tensor& H,
                                                                           const at::Tensor& P) {
  // |p - h|² = |p|² + |h|² - 2 p·h, per frame and hand: [B, T, 2, 1024, J].
  const at::Tensor p = P.unsqueeze(0).unsqueeze(2);                      // [1, T, 1, 1024, 3]
  const at::Tensor cross = at::matmul(p, H.transpose(-1, -2));           // [B, T, 2, 1024, J]
  const at::Tensor d2 = (p * p).sum(-1, true) + (H * H).sum(-1).unsqueeze(-2) - 2.0 * cross;
  const auto [m, idx] = d2.min(-1);
  return {m.clamp_min(0.0).sqrt(), idx};
}

at::Tensor ContactMapGuidance::targets(std::int64_t first, std::int64_t T, std::int64_t B) const {
  at::Tensor t = target_.slice(1, first, first + T);
  if (t.size(0) == B) return t;
  if (t.size(0) == 1) return t.expand({B, T, 2, 1024});
  throw Error("contact-map guidance: " + std::to_string(B) + " samples, but " + std::to_string(t.size(0)) +
              " target contact maps");
}

at::Tensor ContactMapGuidance::discrepancy(const at::Tensor& x0, std::int64_t first) const {
  const auto B = x0.size(0), T = x0.size(1);
  const at::Tensor H = x0.slice(-1, 0, 600).reshape({B, T, 2, kHandKeypoints, 3});
  const auto [dist, idx] = keypoint_contact_map(H, points_.slice(0, first, first + T));
  return (dist - targets(first, T, B)).pow(2).mean({1, 2, 3});
}

at::Tensor ContactMapGuidance::correction(const at::Tensor& x0, std::int64_t first, int /*step*/,
                                          int /*num_steps*/) const {
  const auto B = x0.size(0), T = x0.size(1);
  if (x0.dim() != 3 || x0.size(2) != kHandFeatureSize)
    throw Error("contact-map guidance: x0 must be [B, T, 1200], got " + c10::str(x0.sizes()));
  if (first < 0 || first + T > points_.size(0))
    throw Error("contact-map guidance: frames [" + std::to_string(first) + ", " + std::to_string(first + T) +
                ") outside the " + std::to_string(points_.size(0)) + " frames it was made for");
  at::Tensor out = at::zeros_like(x0);
  if (scale_ == 0.0) return out;
  const at::Tensor H = x0.slice(-1, 0, 600).to(at::kFloat).reshape({B, T, 2, kHandKeypoints, 3});
  const at::Tensor P = points_.slice(0, first, first + T);               // [T, 1024, 3]
  const auto [dist, idx] = keypoint_contact_map(H, P);                   // [B, T, 2, 1024]
  const at::Tensor diff = dist - targets(first, T, B);
  // d/dh of mean((|p - h*| - c)²) = 2 (d - c) / n · (h* - p) / d, summed onto h*.
  const double n = static_cast<double>(T) * 2 * 1024;
  const at::Tensor coef = (2.0 / n) * diff / dist.clamp_min(1e-6);        // [B, T, 2, 1024]
  const at::Tensor nearest = H.gather(3, idx.unsqueeze(-1).expand({B, T, 2, 1024, 3}));
  const at::Tensor per_point = coef.unsqueeze(-1) * (nearest - P.unsqueeze(0).unsqueeze(2));
  at::Tensor grad = at::zeros_like(H);
  grad.scatter_add_(3, idx.unsqueeze(-1).expand({B, T, 2, 1024, 3}), per_point);
  const at::Tensor norm = grad.reshape({B, -1}).norm(2, 1).clamp_min(1e-12).view({B, 1, 1, 1, 1});
  const at::Tensor step_h = (-scale_ * grad / norm).reshape({B, T, 600});
  out.slice(-1, 0, 600).copy_(step_h);
  out.slice(-1, 600, 1200).copy_(-step_h);
  return out.to(x0.scalar_type());
}

}  // namespace bimart::diffusion
