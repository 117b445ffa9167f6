#include "core/diffusion/contact_support.h"

#include <ATen/ATen.h>

#include <limits>
#include <string>

#include "core/util/error.h"

namespace bimart::diffusion {
namespace {

at::Tensor frame_mask(const std::vector<bool>& v) {
  at::Tensor m = at::zeros({static_cast<std::int64_t>(v.size())}, at::kBool);
  for (size_t t = 0; t < v.size(); ++t)
    if (v[t]) m[static_cast<std::int64_t>(t)] = true;
  return m;
}

// In frames `need` [N] where no hand's map restricted to `where` [N, M] comes below the
// threshold, the nearest hand's entries on `where` are shifted down by their minimum.
at::Tensor shift_nearest(const at::Tensor& C, const at::Tensor& need, const at::Tensor& where, double threshold) {
  const at::Tensor w = where.unsqueeze(0).unsqueeze(2);                                     // [1, N, 1, M]
  const at::Tensor masked = C.masked_fill(~w, std::numeric_limits<float>::infinity());
  const at::Tensor mins = std::get<0>(masked.min(-1));                                    // [S, N, 2]
  const at::Tensor untouched = (mins >= threshold).all(-1) & need.unsqueeze(0);          // [S, N]
  const at::Tensor nearest = at::one_hot(mins.argmin(-1), 2).to(at::kBool);              // [S, N, 2]
  const at::Tensor shift = at::where(nearest & untouched.unsqueeze(-1) & at::isfinite(mins), mins,
                                     at::zeros_like(mins));
  return (C - shift.unsqueeze(-1) * w.to(at::kFloat)).clamp_min(0);
}

}  // namespace

at::Tensor hold_contacts(const at::Tensor& maps, const std::vector<bool>& held, const std::vector<bool>& turning,
                         const at::Tensor& top, double threshold) {
  if (maps.dim() != 4 || maps.size(2) != 2 || top.dim() != 2 || top.size(0) != maps.size(1) ||
      top.size(1) != maps.size(3) || static_cast<std::int64_t>(held.size()) != maps.size(1) ||
      static_cast<std::int64_t>(turning.size()) != maps.size(1))
    throw Error("contact support: need maps [S, N, 2, M], top [N, M] and N held and turning flags, got " +
                c10::str(maps.sizes()) + ", " + c10::str(top.sizes()) + ", " + std::to_string(held.size()) +
                " and " + std::to_string(turning.size()));
  if (!(threshold > 0)) throw Error("contact support: threshold must be > 0 (metres)");
  const at::Tensor is_top = top.to(at::kBool);
  at::Tensor C = maps.to(at::kFloat);
  C = shift_nearest(C, frame_mask(held), at::ones_like(is_top), threshold);
  return shift_nearest(C, frame_mask(turning), is_top, threshold).contiguous();
}

std::vector<bool> around_motion(const std::vector<bool>& moving) {
  std::vector<bool> held(moving.size(), false);
  for (size_t t = 0; t < moving.size(); ++t)
    held[t] = moving[t] || (t > 0 && moving[t - 1]);
  return held;
}

}  // namespace bimart::diffusion
