#include "core/diffusion/contact_placement.h"

#include <ATen/ATen.h>

#include <cmath>
#include <string>

#include "core/diffusion/contact_guidance.h"
#include "core/util/error.h"

namespace bimart::diffusion {

void PlacementOptions::validate() const {
  if (!(threshold > 0) || !std::isfinite(threshold)) throw Error("contact placement: threshold must be > 0 (metres)");
  if (iterations < 1) throw Error("contact placement: iterations must be >= 1");
  if (min_points < 1) throw Error("contact placement: min_points must be >= 1");
  if (!(sigma >= 0) || !std::isfinite(sigma)) throw Error("contact placement: sigma must be >= 0 (frames)");
  if (!(snap >= 0) || !std::isfinite(snap)) throw Error("contact placement: snap must be >= 0 (metres)");
  if (!std::isfinite(depth)) throw Error("contact placement: depth must be finite (metres)");
}

at::Tensor smooth_over_frames(const at::Tensor& delta, const at::Tensor& w, double sigma) {
  if (sigma <= 0) return delta * w.unsqueeze(-1);
  const std::int64_t T = delta.size(1);
  const at::Tensor t = at::arange(T, at::kFloat);
  const at::Tensor g = at::exp(-(t.view({T, 1}) - t.view({1, T})).pow(2) / (2 * sigma * sigma));  // [T, T]
  const at::Tensor num = at::einsum("ts,bshc->bthc", {g, delta * w.unsqueeze(-1)});
  const at::Tensor den = at::einsum("ts,bsh->bth", {g, w}).clamp_min(1.0);
  return num / den.unsqueeze(-1);
}

at::Tensor contact_translations(const at::Tensor& keypoints, const at::Tensor& object_points,
                                const at::Tensor& contact_maps, const PlacementOptions& o) {
  o.validate();
  const at::Tensor H0 = keypoints.to(at::kFloat);
  const at::Tensor P = object_points.to(at::kFloat);
  at::Tensor C = contact_maps.to(at::kFloat);
  if (H0.dim() != 5 || H0.size(2) != 2 || H0.size(4) != 3 || P.dim() != 3 || P.size(0) != H0.size(1) ||
      P.size(2) != 3 || C.dim() != 4 || C.size(0) != H0.size(0) || C.size(1) != H0.size(1) || C.size(2) != 2 ||
      C.size(3) != P.size(1))
    throw Error("contact placement: need keypoints [B, T, 2, J, 3], object points [T, M, 3] and contact maps "
                "[B, T, 2, M], got " + c10::str(H0.sizes()) + ", " + c10::str(P.sizes()) + " and " +
                c10::str(C.sizes()));
  const std::int64_t B = H0.size(0), T = H0.size(1), M = P.size(1);
  if (o.snap > o.threshold) {  // nearly touching hands: the map shifted down by its minimum
    const at::Tensor m = std::get<0>(C.min(-1, true));
    C = C - m * ((m >= o.threshold) & (m < o.snap)).to(at::kFloat);
  }
  const at::Tensor contact = (C < o.threshold).to(at::kFloat);                         // [B, T, 2, M]
  const at::Tensor count = contact.sum(-1);                                           // [B, T, 2]
  const at::Tensor w = (count >= static_cast<double>(o.min_points)).to(at::kFloat);  // frames with contacts
  const at::Tensor Pb = P.view({1, T, 1, M, 3});
  at::Tensor delta = at::zeros({B, T, 2, 3}, at::kFloat);
  for (int it = 0; it < o.iterations; ++it) {
    const at::Tensor H = H0 + delta.unsqueeze(3);
    const at::Tensor idx = ContactMapGuidance::keypoint_contact_map(H, P).second;  // [B, T, 2, M]
    const at::Tensor nearest = H.gather(3, idx.unsqueeze(-1).expand({B, T, 2, M, 3}));
    const at::Tensor to_point = Pb - nearest;                                       // k → p
    const at::Tensor d = to_point.norm(2, -1).clamp_min(1e-6);
    // The keypoint's target lies on the segment p → k at distance C from p.
    const at::Tensor step = to_point * ((1 - (C - o.depth) / d) * contact).unsqueeze(-1);  // target − k
    delta = delta + w.unsqueeze(-1) * step.sum(3) / count.clamp_min(1).unsqueeze(-1);
  }
  return smooth_over_frames(delta, w, o.sigma).contiguous();
}

}  // namespace bimart::diffusion
