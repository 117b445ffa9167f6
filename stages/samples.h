// Several samples in one run. The diffusion stages generate S samples as one batch
// (`contact_maps_samples` [S, N, 2, 1024], `hand_keypoints_samples` [S, N, 1200]); the
// refiners refine each of them (`hand_samples`, stages/refiner.h); exporters and metrics
// that take these optional inputs handle every sample. Sample 0 is also each stage's
// single output (`contact_maps`, `hand_keypoints`, `hand_params`), so a pipeline that
// knows nothing of samples runs as before.
//
// A per-file exporter writes one file per sample when its `path` holds the placeholder
// `{sample}` (fmt syntax: `{sample:02d}` pads), e.g. `out/sample_{sample}.npz` gives
// sample_0.npz, sample_1.npz, ...; without it, it writes sample 0 to `path`.
#pragma once

#include <fmt/format.h>

#include <string>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/hand/hand_motion.h"
#include "core/pipeline/stage.h"
#include "core/util/error.h"

namespace bimart {

// The optional sample inputs and the `paths` output (every file written).
inline StageSpec& declare_sample_ports(StageSpec& s) {
  return s
      .optional_input<std::vector<HandMotion>>("hand_samples",
                                               "S refined motions, one per sample (a refiner's); sample 0 is hand_params")
      .optional_input<at::Tensor>("contact_maps_samples",
                                  "[S, N, 2, 1024] float32, m: the contact map that conditioned each sample")
      .output<std::vector<std::string>>("paths", "every file written (one per sample, or one)");
}

struct StageSample {
  const HandMotion* hands = nullptr;
  at::Tensor contact_maps;  // [N, 2, 1024], undefined when none is wired
};

// Every sample on the stage's inputs: `hand_samples` with the matching entry of
// `contact_maps_samples` (or `contact_maps` when the contact stage made one map for all),
// or the single `hand_params` with `contact_maps`.
inline std::vector<StageSample> stage_samples(StageIO& io) {
  const at::Tensor single = io.has("contact_maps") ? io.in<at::Tensor>("contact_maps") : at::Tensor();
  std::vector<StageSample> out;
  if (!io.has("hand_samples")) {
    out.push_back({&io.in<HandMotion>("hand_params"), single});
    return out;
  }
  const auto& hands = io.in<std::vector<HandMotion>>("hand_samples");
  if (hands.empty()) throw Error("hand_samples is empty");
  at::Tensor per_sample;
  if (io.has("contact_maps_samples") &&
      io.in<at::Tensor>("contact_maps_samples").size(0) == static_cast<std::int64_t>(hands.size()))
    per_sample = io.in<at::Tensor>("contact_maps_samples");
  for (std::size_t k = 0; k < hands.size(); ++k)
    out.push_back({&hands[k], per_sample.defined() ? per_sample[static_cast<std::int64_t>(k)] : single});
  return out;
}

inline bool has_sample_placeholder(const std::string& path) { return path.find("{sample") != std::string::npos; }

// `path` with {sample} replaced by k; throws bimart::Error for a malformed placeholder.
inline std::string sample_path(const std::string& path, std::size_t k) {
  if (!has_sample_placeholder(path)) return path;
  try {
    return fmt::format(fmt::runtime(path), fmt::arg("sample", k));
  } catch (const fmt::format_error& e) {
    throw Error("path '" + path + "': bad {sample} placeholder (" + e.what() + "; write {sample} or {sample:02d})");
  }
}

}  // namespace bimart
