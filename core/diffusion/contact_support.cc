#include "core/diffusion/contact_support.h"

#include <ATen/ATen.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/diffusion/contact_placement.h"
#include "core/util/error.h"

namespace bimart::diffusion {
namespace {

at::Tensor frame_mask(const std::vector<bool>& v) {
  at::Tensor m = at::zeros({static_cast<std::int64_t>(v.size())}, at::kBool);
  for (size_t t = 0; t < v.size(); ++t)
    if (v[t]) m[static_cast<std::int64_t>(t)] = true;
  return m;
}

// [N, 2] bool: every hand may, unless `may` says otherwise.
at::Tensor eligible(const at::Tensor& may, std::int64_t N) {
  if (!may.defined()) return at::ones({N, 2}, at::kBool);
  if (may.dim() != 2 || may.size(0) != N || may.size(1) != 2)
    throw Error("contact support: the hands that may hold must be [" + std::to_string(N) + ", 2], got " +
                c10::str(may.sizes()));
  return may.to(at::kBool);
}

// In frames `need` [N] where no hand's map restricted to `where` [N, M] comes below the
// threshold, the nearest hand (among those `may` [N, 2]) has its entries on `where`
// shifted down by their minimum.
at::Tensor shift_nearest(const at::Tensor& C, const at::Tensor& need, const at::Tensor& where, double threshold,
                         const at::Tensor& may) {
  const at::Tensor w = where.unsqueeze(0).unsqueeze(2);                                     // [1, N, 1, M]
  const at::Tensor masked = C.masked_fill(~w, std::numeric_limits<float>::infinity());
  const at::Tensor mins = std::get<0>(masked.min(-1)).masked_fill(~may.unsqueeze(0), std::numeric_limits<float>::infinity());  // [S, N, 2]
  const at::Tensor untouched = (mins >= threshold).all(-1) & need.unsqueeze(0);          // [S, N]
  const at::Tensor nearest = at::one_hot(mins.argmin(-1), 2).to(at::kBool);              // [S, N, 2]
  const at::Tensor shift = at::where(nearest & untouched.unsqueeze(-1) & at::isfinite(mins), mins,
                                     at::zeros_like(mins));
  return (C - shift.unsqueeze(-1) * w.to(at::kFloat)).clamp_min(0);
}

constexpr int kSupportRounds = 4;    // rounds of support_translations
constexpr int kSupportKeypoint = 3;  // a hand's distance is its 3rd nearest keypoint's

}  // namespace

at::Tensor hold_contacts(const at::Tensor& maps, const std::vector<bool>& held, const std::vector<bool>& turning,
                         const at::Tensor& top, double threshold, const at::Tensor& may_hold,
                         const at::Tensor& may_hold_top) {
  if (maps.dim() != 4 || maps.size(2) != 2 || top.dim() != 2 || top.size(0) != maps.size(1) ||
      top.size(1) != maps.size(3) || static_cast<std::int64_t>(held.size()) != maps.size(1) ||
      static_cast<std::int64_t>(turning.size()) != maps.size(1))
    throw Error("contact support: need maps [S, N, 2, M], top [N, M] and N held and turning flags, got " +
                c10::str(maps.sizes()) + ", " + c10::str(top.sizes()) + ", " + std::to_string(held.size()) +
                " and " + std::to_string(turning.size()));
  if (!(threshold > 0)) throw Error("contact support: threshold must be > 0 (metres)");
  const at::Tensor is_top = top.to(at::kBool);
  at::Tensor C = maps.to(at::kFloat);
  const std::int64_t N = maps.size(1);
  C = shift_nearest(C, frame_mask(held), at::ones_like(is_top), threshold, eligible(may_hold, N));
  return shift_nearest(C, frame_mask(turning), is_top, threshold, eligible(may_hold_top, N)).contiguous();
}

at::Tensor support_translations(const at::Tensor& keypoints, const at::Tensor& object_points,
                                const std::vector<bool>& held, const std::vector<bool>& turning, const at::Tensor& top,
                                double reach, double sigma, const at::Tensor& may_hold,
                                const at::Tensor& may_hold_top) {
  const at::Tensor H = keypoints.to(at::kFloat);
  const at::Tensor P = object_points.to(at::kFloat);
  if (H.dim() != 5 || H.size(2) != 2 || H.size(4) != 3 || P.dim() != 3 || P.size(0) != H.size(1) || P.size(2) != 3 ||
      top.dim() != 2 || top.size(0) != P.size(0) || top.size(1) != P.size(1) ||
      static_cast<std::int64_t>(held.size()) != H.size(1) || static_cast<std::int64_t>(turning.size()) != H.size(1))
    throw Error("support placement: need keypoints [B, T, 2, J, 3], object points [T, M, 3], top [T, M] and T held "
                "and turning flags, got " + c10::str(H.sizes()) + ", " + c10::str(P.sizes()) + ", " +
                c10::str(top.sizes()) + ", " + std::to_string(held.size()) + " and " + std::to_string(turning.size()));
  if (!(reach > 0) || !std::isfinite(reach)) throw Error("support placement: reach must be > 0 (metres)");
  if (!(sigma >= 0) || !std::isfinite(sigma)) throw Error("support placement: sigma must be >= 0 (frames)");
  const std::int64_t B = H.size(0), T = H.size(1), J = H.size(3), M = P.size(1);
  const float inf = std::numeric_limits<float>::infinity();
  const at::Tensor is_top = top.to(at::kBool);
  struct Pass {
    at::Tensor need_frame, where, may;
  };
  const Pass passes[] = {{frame_mask(held), at::ones_like(is_top), eligible(may_hold, T)},
                         {frame_mask(turning), is_top, eligible(may_hold_top, T)}};
  // Smoothing shortens the moves near the ends of a stretch and between frames whose
  // nearest points differ, so the frames still apart are moved again (a few rounds).
  at::Tensor total = at::zeros({B, T, 2, 3}, at::kFloat);
  for (int round = 0; round < kSupportRounds; ++round) {
    at::Tensor delta = at::zeros({B, T, 2, 3}, at::kFloat);
    at::Tensor w = at::zeros({B, T, 2}, at::kFloat);
    for (const auto& [need_frame, where, may] : passes) {
      const at::Tensor Hd = H + (total + delta).unsqueeze(3);
      // Each keypoint's nearest object point (among `where`), sample by sample.
      at::Tensor gap = at::empty({B, T, 2, J}, at::kFloat), near = at::empty({B, T, 2, J}, at::kLong);
      for (std::int64_t b = 0; b < B; ++b) {
        const at::Tensor d = at::cdist(Hd[b].reshape({T, 2 * J, 3}), P).masked_fill(~where.view({T, 1, M}), inf);
        const auto [v, i] = d.min(-1);  // [T, 2J]
        gap[b] = v.view({T, 2, J});
        near[b] = i.view({T, 2, J});
      }
      // A hand's distance: its k-th nearest keypoint's (not the nearest: a stray keypoint
      // far from the others is not where the fitted hand will be).
      auto [hand_gap, kp] = gap.kthvalue(std::min<std::int64_t>(kSupportKeypoint, J), -1);  // [B, T, 2]
      hand_gap = hand_gap.masked_fill(~may.unsqueeze(0), inf);
      const at::Tensor need = (hand_gap >= reach).all(-1) & need_frame.view({1, T}) & at::isfinite(hand_gap).any(-1);
      const at::Tensor move = at::one_hot(hand_gap.argmin(-1), 2).to(at::kBool) & need.unsqueeze(-1);  // [B, T, 2]
      const at::Tensor k = Hd.gather(3, kp.view({B, T, 2, 1, 1}).expand({B, T, 2, 1, 3})).squeeze(3);
      const at::Tensor pi = near.gather(3, kp.unsqueeze(-1)).squeeze(-1);  // [B, T, 2]
      const at::Tensor p = P.view({1, T, 1, M, 3}).expand({B, T, 2, M, 3}).gather(3, pi.view({B, T, 2, 1, 1}).expand({B, T, 2, 1, 3})).squeeze(3);
      delta = delta + (p - k) * move.unsqueeze(-1).to(at::kFloat);
      w = at::maximum(w, move.to(at::kFloat));
    }
    if (!w.any().item<bool>()) break;
    total = total + smooth_over_frames(delta, w, sigma);
  }
  return total.contiguous();
}

}  // namespace bimart::diffusion
