// The contact cue: a few numbers per frame and hand that say, in the canonical object frame,
// where the contact map C puts the hand (docs/training.md, "Contact cue"). C holds each
// object point's distance to the nearest point of the hand, indexed by basis row; which 3D
// point a row is differs per object, so a network reading C alone must learn to pair rows
// with the BPS features' positions — the motion model did so poorly (69 mm keypoint error
// at the noisiest step with the true C). The cue does the pairing explicitly: per hand and
// temperature σ, the softmin(C/σ)-weighted mean and covariance of the object points and
// the weights' effective count, plus the smallest distance.
#pragma once

#include <ATen/core/Tensor.h>

namespace bimart {

enum class BpsVariant;  // core/features/bps.h

constexpr int kContactCueTemperatures = 3;                                // σ = 1, 3, 10 cm
constexpr int kContactCuePerHand = kContactCueTemperatures * 10 + 1;     // μ 3, cov 6, count 1; d_min
constexpr int kContactCueSize = 2 * kContactCuePerHand;                   // 62, left hand first

// The cue [..., 62] float32 from the object points [..., 1024, 3] (metres, canonical frame)
// and the contact maps [..., 2, 1024] (metres) of the same frames. Positions are in
// decimetres, covariances in dm², distances in dm, counts as log(count) / 3, so that the
// entries are of order one.
at::Tensor contact_cue(const at::Tensor& points, const at::Tensor& contact_maps);

// The object points [..., 1024, 3] (metres, canonical frame) of the BPS features O
// [..., 1024, 3] (encoder space: the hit point minus its basis point), the basis points
// [1024, 3] and the scale of encoder space ([...] or a number: s_o for NP-BPS and NPA-BPS,
// 1 for U-BPS).
at::Tensor object_points_from_bps(const at::Tensor& object_features, const at::Tensor& basis_points,
                                  const at::Tensor& scale);
// The same with the scale chosen by the encoder variant: `object_scale` s_o ([...] or a
// number, e.g. G's last entry) for NPA-BPS and NP-BPS, 1 for U-BPS (metres already).
at::Tensor object_points_from_bps(const at::Tensor& object_features, const at::Tensor& basis_points,
                                  const at::Tensor& object_scale, BpsVariant variant);

}  // namespace bimart
