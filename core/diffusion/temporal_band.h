// Band-limiting a window over time: the projection onto the lowest `keep` frequencies of
// the orthonormal DCT-II over its frames. Hand motion and contact maps are smooth (the
// data's keypoint acceleration is ~0.4 mm/frame²), so their windows lie almost entirely in
// a low band; a denoiser's per-frame errors do not, and are what makes samples jitter.
// Sampling can project each x0 prediction onto the band (GenerateOptions::band).
#pragma once

#include <cstdint>

#include <ATen/core/Tensor.h>

namespace bimart::diffusion {

// The [frames, frames] projection Qₖᵀ Qₖ (Qₖ: the first `keep` rows of the DCT-II matrix).
// keep >= frames gives the identity. Throws for frames < 1 or keep < 1.
at::Tensor band_projection(std::int64_t frames, std::int64_t keep);

// x [..., frames, D] projected over its frame axis (dim -2) onto the lowest `keep`
// frequencies; x itself when keep <= 0 or keep >= frames.
at::Tensor band_limit(const at::Tensor& x, std::int64_t keep);

// x [..., frames, D] times a projection from band_projection (built once per sampling
// run, not per step); x itself when the projection is undefined.
at::Tensor band_limit(const at::Tensor& x, const at::Tensor& projection);

}  // namespace bimart::diffusion
