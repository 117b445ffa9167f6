// Per-feature normalisation of the diffusion models' data (DESIGN §5: "data normalised per
// feature by mean/std stored with the model"; docs/data_loader.md): mean and standard
// deviation of
//   X (1200)                       hand features, the motion model's sample,
//   [O flattened | G] (3072 + 7)   the object condition of both models,
//   C (2048)                       contact maps, the contact model's sample and the motion
//                                  model's condition,
//   MANO-Rep (294)                 when the data set holds it (WindowDatasetOptions::mano):
//                                  a MANO-Rep motion model's sample,
// over the TRAIN split only. Statistics are taken over every (window, real frame) pair —
// each frame weighted by the number of windows it appears in, padding excluded — which is
// the distribution WindowDataset::batch draws from; G's translation is per window anyway.
// Accumulated in float64: per sequence (two passes), then combined in sequence order
// (Chan et al.'s update). Standard deviations are floored at
// `std_floor` (default 1e-3 in the feature's units, see the docs) so that a feature that is
// constant on the training data is centred but not blown up on new data.
#pragma once

#include <cstdint>
#include <string>

#include <ATen/core/Tensor.h>

namespace bimart {

class WindowDataset;
class NpzFile;

constexpr double kNormalizationStdFloor = 1e-3;
constexpr int kObjectConditionSize = 1024 * 3 + 7;  // [O | G] per frame

struct NormalizationStats {
  std::string variant;     // encoder variant of O, e.g. "np_bps"
  std::int64_t count = 0;  // (window, frame) pairs the statistics were taken over
  double std_floor = kNormalizationStdFloor;
  // float64; std already floored.
  at::Tensor x_mean, x_std;      // [1200]
  at::Tensor obj_mean, obj_std;  // [3079]
  at::Tensor c_mean, c_std;      // [2048]
  at::Tensor mano_mean, mano_std;  // [294] MANO-Rep; undefined unless computed from a data set holding it
  // > 0: C is normalised in log space, z = (log(C + c_log_eps) − c_mean) / c_std (metres; a
  // contact model's sample, so that the few centimetres that decide contact are not lost
  // beside distances of 30 cm); 0: z = (C − c_mean) / c_std.
  double c_log_eps = 0;
  // Defined: the contact model's sample is the normalised maps projected, per hand, onto
  // these K orthonormal directions [1024, K] (float64, the principal directions of the
  // training maps, contact_basis()): 2K numbers per frame instead of 2048, so that a narrow
  // network can carry its noisy input (docs/training.md, "Contact basis"). Undefined: the
  // 2048 normalised values.
  at::Tensor c_basis;

  // X [..., 1200] -> normalised, same shape and dtype; and back.
  at::Tensor normalize_x(const at::Tensor& x) const;
  at::Tensor denormalize_x(const at::Tensor& x) const;
  // MANO-Rep [..., 294] -> normalised, and back; throws when the statistics have none.
  at::Tensor normalize_mano(const at::Tensor& m) const;
  at::Tensor denormalize_mano(const at::Tensor& m) const;
  // Both hands' joints [..., 96] (MANO-Rep's joint columns) with those columns' statistics.
  at::Tensor normalize_joints(const at::Tensor& j) const;
  at::Tensor denormalize_joints(const at::Tensor& j) const;
  // O [..., 1024, 3] and G [..., 7] -> the normalised object condition [..., 3079].
  at::Tensor normalize_object(const at::Tensor& object_features, const at::Tensor& global_states) const;
  // C [..., 2, 1024] -> normalised (in log space when c_log_eps > 0), same shape; and back.
  at::Tensor normalize_c(const at::Tensor& c) const;
  at::Tensor denormalize_c(const at::Tensor& c) const;
  // The contact model's sample: C [..., 2, 1024] (metres) -> [..., contact_sample_size()],
  // normalised and (with c_basis) projected; and back to metres [..., 2, 1024] (not clamped).
  at::Tensor contact_sample(const at::Tensor& c) const;
  at::Tensor contact_from_sample(const at::Tensor& z) const;
  std::int64_t contact_sample_size() const;
};

// Over all windows of `train` (which should hold the train split). Throws when it is empty.
// c_log_eps > 0: C's statistics are of log(C + c_log_eps) (see NormalizationStats).
NormalizationStats compute_normalization(const WindowDataset& train, double std_floor = kNormalizationStdFloor,
                                         double c_log_eps = 0);

// The first k principal directions [1024, k] (float64, by decreasing variance, each with
// its largest entry positive) of `stats`' normalised contact maps over `train`'s windows,
// the two hands pooled, frames weighted as compute_normalization weights them. Throws for
// k outside [1, 1024].
at::Tensor contact_basis(const WindowDataset& train, const NormalizationStats& stats, int k);

// .npz with keys x_mean, x_std, obj_mean, obj_std, c_mean, c_std (f8), variant (string),
// count (i8), std_floor (f8), format_version (i8), and c_log_eps (f8), c_basis (f8
// [1024, K]) and mano_mean, mano_std (f8 [294]) when set; written atomically.
void save_normalization(const NormalizationStats& stats, const std::string& path);
// Throws bimart::Error naming the file and key on a missing key, a wrong shape or a
// standard deviation that is not positive and finite.
NormalizationStats load_normalization(const std::string& path);

// The same keys with a prefix, inside another archive (a model checkpoint).
void store_normalization(const NormalizationStats& stats, NpzFile& file, const std::string& prefix);
NormalizationStats read_normalization(const NpzFile& file, const std::string& prefix);

// [O flattened | G]: O [..., 1024, 3], G [..., 7] -> [..., 3079].
at::Tensor object_condition(const at::Tensor& object_features, const at::Tensor& global_states);
// (x - mean) / std and x * std + mean over the last dimension (mean, std [F]; broadcast
// over the leading ones), in x's dtype.
at::Tensor normalize(const at::Tensor& x, const at::Tensor& mean, const at::Tensor& std);
at::Tensor denormalize(const at::Tensor& x, const at::Tensor& mean, const at::Tensor& std);

}  // namespace bimart
