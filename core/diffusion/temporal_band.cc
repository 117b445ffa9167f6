#include "core/diffusion/temporal_band.h"

#include <ATen/ATen.h>

#include <string>

#include "core/diffusion/denoiser.h"
#include "core/util/error.h"

namespace bimart::diffusion {

at::Tensor band_projection(std::int64_t frames, std::int64_t keep) {
  if (frames < 1 || keep < 1)
    throw Error("band projection: need frames >= 1 and keep >= 1, got " + std::to_string(frames) + " and " +
                std::to_string(keep));
  if (keep >= frames) return at::eye(frames, at::kFloat);
  const at::Tensor q = dct_matrix(frames).slice(0, 0, keep);  // [keep, frames]
  return at::matmul(q.t(), q);
}

at::Tensor band_limit(const at::Tensor& x, std::int64_t keep) {
  if (x.dim() < 2) throw Error("band limit: need [..., frames, D], got " + c10::str(x.sizes()));
  const std::int64_t frames = x.size(-2);
  if (keep <= 0 || keep >= frames) return x;
  return band_limit(x, band_projection(frames, keep));
}

at::Tensor band_limit(const at::Tensor& x, const at::Tensor& projection) {
  if (!projection.defined()) return x;
  if (x.dim() < 2 || projection.dim() != 2 || projection.size(0) != x.size(-2) || projection.size(1) != x.size(-2))
    throw Error("band limit: projection " + c10::str(projection.sizes()) + " does not fit " + c10::str(x.sizes()));
  return at::matmul(projection.to(x.scalar_type()), x);
}

}  // namespace bimart::diffusion
