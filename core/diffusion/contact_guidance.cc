#include "core/diffusion/contact_guidance.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/diffusion/contact_support.h"
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

void ContactMapGuidance::set_placement(int steps, const PlacementOptions& options) {
  if (steps < 0) throw Error("contact-map guidance: placement steps must be >= 0");
  options.validate();
  place_steps_ = steps;
  placement_ = options;
}

void ContactMapGuidance::set_release(int steps) {
  if (steps < 0) throw Error("contact-map guidance: release steps must be >= 0");
  release_steps_ = steps;
}

void ContactMapGuidance::set_support(std::vector<bool> held, std::vector<bool> turning, at::Tensor top, double reach,
                                     at::Tensor may_hold, at::Tensor may_hold_top) {
  const auto N = points_.size(0);
  if (static_cast<std::int64_t>(held.size()) != N || static_cast<std::int64_t>(turning.size()) != N ||
      top.dim() != 2 || top.size(0) != N || top.size(1) != points_.size(1))
    throw Error("contact-map guidance: support needs " + std::to_string(N) + " held and turning flags and top [" +
                std::to_string(N) + ", " + std::to_string(points_.size(1)) + "], got " + std::to_string(held.size()) +
                ", " + std::to_string(turning.size()) + " and " + c10::str(top.sizes()));
  if (!(reach > 0) || !std::isfinite(reach)) throw Error("contact-map guidance: support reach must be > 0 (metres)");
  support_ = true;
  held_ = std::move(held);
  turning_ = std::move(turning);
  top_ = top.to(at::kBool).contiguous();
  reach_ = reach;
  may_hold_ = std::move(may_hold);
  may_hold_top_ = std::move(may_hold_top);
}

namespace {

// The nearest of J keypoints (kx, ky, kz) for each of M points (px, py, pz): squared
// distance and index (the first keypoint on a tie). The inner loop runs over the points
// with no branch, so the compiler vectorises it; built for AVX-512, AVX2 and the baseline,
// the best one picked when the library loads.
__attribute__((target_clones("avx512f", "avx2", "default"))) void nearest_block(
    const float* __restrict kx, const float* __restrict ky, const float* __restrict kz, int J,
    const float* __restrict px, const float* __restrict py, const float* __restrict pz, int M, float* __restrict best,
    int* __restrict idx) {
  for (int m = 0; m < M; ++m) best[m] = std::numeric_limits<float>::infinity(), idx[m] = 0;
  for (int j = 0; j < J; ++j) {
    const float x = kx[j], y = ky[j], z = kz[j];
    for (int m = 0; m < M; ++m) {
      const float dx = x - px[m], dy = y - py[m], dz = z - pz[m];
      const float d2 = dx * dx + dy * dy + dz * dz;
      // Min and a bit-mask blend, not `closer ? ... : ...`: GCC turns that into masked
      // stores behind a data-dependent branch, which mispredicts (2x slower).
      const int closer = -static_cast<int>(d2 < best[m]);
      best[m] = std::min(d2, best[m]);
      idx[m] = (idx[m] & ~closer) | (j & closer);
    }
  }
}

// For every block (sample b, frame t, hand h) of keypoints H [B, T, 2, J, 3] and object
// points P [T, M, 3] (both float), calls visit(block, point, nearest, dist)
// for each of the M points with its nearest keypoint. Brute force over the J keypoints,
// blocks in parallel: J = 100 is too few for a tree to pay, and the batched matrix product
// this replaces allocated [B, T, 2, 1024, J] temporaries — 0.6 s a step for two samples,
// mostly page faults — where this needs none.
template <class Visit>
void for_each_nearest(const at::Tensor& H, const at::Tensor& P, Visit&& visit) {
  const std::int64_t B = H.size(0), T = H.size(1), J = H.size(3), M = P.size(1);
  // Structure of arrays (x..., y..., z...) per block of keypoints and per frame of points.
  const at::Tensor k_soa = H.transpose(-1, -2).contiguous();  // [B, T, 2, 3, J]
  const at::Tensor p_soa = P.transpose(-1, -2).contiguous();  // [T, 3, M]
  const float* k = k_soa.data_ptr<float>();
  const float* q0 = p_soa.data_ptr<float>();
  at::parallel_for(0, B * T * 2, 1, [&](std::int64_t begin, std::int64_t end) {
    std::vector<float> best(static_cast<std::size_t>(M));
    std::vector<int> idx(static_cast<std::size_t>(M));
    for (std::int64_t blk = begin; blk < end; ++blk) {
      const float* kb = k + blk * 3 * J;
      const float* q = q0 + ((blk / 2) % T) * 3 * M;
      nearest_block(kb, kb + J, kb + 2 * J, static_cast<int>(J), q, q + M, q + 2 * M, static_cast<int>(M), best.data(),
                    idx.data());
      for (std::int64_t m = 0; m < M; ++m) visit(blk, m, idx[static_cast<std::size_t>(m)], std::sqrt(best[static_cast<std::size_t>(m)]));
    }
  });
}

at::Tensor keypoint_blocks(const at::Tensor& H) {
  if (H.dim() != 5 || H.size(2) != 2 || H.size(4) != 3)
    throw Error("contact-map guidance: keypoints must be [B, T, 2, J, 3], got " + c10::str(H.sizes()));
  return H.to(at::kFloat).contiguous();
}

}  // namespace

std::pair<at::Tensor, at::Tensor> ContactMapGuidance::keypoint_contact_map(const at::Tensor& keypoints,
                                                                           const at::Tensor& object_points) {
  const at::Tensor H = keypoint_blocks(keypoints);
  const at::Tensor P = object_points.to(at::kFloat).contiguous();
  if (P.dim() != 3 || P.size(0) != H.size(1) || P.size(2) != 3)
    throw Error("contact-map guidance: object points must be [T, M, 3] with T = " + std::to_string(H.size(1)) +
                ", got " + c10::str(P.sizes()));
  const std::int64_t M = P.size(1);
  at::Tensor dist = at::empty({H.size(0), H.size(1), 2, M}, at::kFloat);
  at::Tensor idx = at::empty({H.size(0), H.size(1), 2, M}, at::kLong);
  float* d = dist.data_ptr<float>();
  std::int64_t* i = idx.data_ptr<std::int64_t>();
  for_each_nearest(H, P, [&](std::int64_t blk, std::int64_t m, std::int64_t best, float dm) {
    d[blk * M + m] = dm;
    i[blk * M + m] = best;
  });
  return {dist, idx};
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

void ContactMapGuidance::check_window(const at::Tensor& x0, std::int64_t first) const {
  if (x0.dim() != 3 || x0.size(2) != kHandFeatureSize)
    throw Error("contact-map guidance: x0 must be [B, T, 1200], got " + c10::str(x0.sizes()));
  if (first < 0 || first + x0.size(1) > points_.size(0))
    throw Error("contact-map guidance: frames [" + std::to_string(first) + ", " + std::to_string(first + x0.size(1)) +
                ") outside the " + std::to_string(points_.size(0)) + " frames it was made for");
}

at::Tensor ContactMapGuidance::placement(const at::Tensor& x0, std::int64_t first, int step, int /*num_steps*/) const {
  check_window(x0, first);
  if (step >= place_steps_) return {};
  const auto B = x0.size(0), T = x0.size(1);
  const at::Tensor H = x0.slice(-1, 0, 600).to(at::kFloat).reshape({B, T, 2, kHandKeypoints, 3});
  const at::Tensor P = points_.slice(0, first, first + T);
  at::Tensor delta = contact_translations(H, P, targets(first, T, B), placement_);
  if (support_) {
    const auto frames = [&](const std::vector<bool>& v) { return std::vector<bool>(v.begin() + first, v.begin() + first + T); };
    const auto window = [&](const at::Tensor& m) { return m.defined() ? m.slice(0, first, first + T) : m; };
    delta = delta + support_translations(H + delta.unsqueeze(3), P, frames(held_), frames(turning_),
                                         top_.slice(0, first, first + T), reach_, placement_.sigma,
                                         window(may_hold_), window(may_hold_top_));
  }
  const at::Tensor step_h = delta.unsqueeze(3).expand({B, T, 2, kHandKeypoints, 3}).reshape({B, T, 600});
  return at::cat({step_h, -step_h}, -1).to(x0.scalar_type());  // H moves, H + D stays
}

at::Tensor ContactMapGuidance::correction(const at::Tensor& x0, std::int64_t first, int step,
                                          int /*num_steps*/) const {
  check_window(x0, first);
  const auto B = x0.size(0), T = x0.size(1);
  if (scale_ == 0.0 || step < release_steps_) return at::zeros_like(x0);
  const at::Tensor H = keypoint_blocks(x0.slice(-1, 0, 600).reshape({B, T, 2, kHandKeypoints, 3}));
  const at::Tensor P = points_.slice(0, first, first + T).contiguous();  // [T, 1024, 3]
  const at::Tensor C = targets(first, T, B).contiguous();                 // [B, T, 2, 1024]
  // d/dh of mean((|p - h*| - c)²) = 2 (d - c) / n · (h* - p) / d, summed onto h*; each
  // block owns its keypoints' gradient, so the parallel blocks never write the same entry.
  const double n = static_cast<double>(T) * 2 * 1024;
  at::Tensor grad = at::zeros_like(H);
  float* g = grad.data_ptr<float>();
  const float* h = H.data_ptr<float>();
  const float* c = C.data_ptr<float>();
  const float* p = P.data_ptr<float>();
  for_each_nearest(H, P, [&](std::int64_t blk, std::int64_t m, std::int64_t best, float dm) {
    const float coef = static_cast<float>(2.0 / n) * (dm - c[blk * 1024 + m]) / std::max(dm, 1e-6f);
    const float* k = h + (blk * kHandKeypoints + best) * 3;
    const float* pt = p + (((blk / 2) % T) * 1024 + m) * 3;
    float* gk = g + (blk * kHandKeypoints + best) * 3;
    for (int a = 0; a < 3; ++a) gk[a] += coef * (k[a] - pt[a]);
  });
  const at::Tensor norm = grad.reshape({B, -1}).norm(2, 1).clamp_min(1e-12).view({B, 1, 1, 1, 1});
  const at::Tensor step_h = (-scale_ * grad / norm).reshape({B, T, 600});
  return at::cat({step_h, -step_h}, -1).to(x0.scalar_type());  // H moves, H + D stays
}

}  // namespace bimart::diffusion
