// CAMS-B's manipulation stages (docs/baselines.md): CAMS (Zheng et al. 2023) splits a
// manipulation into stages and gives each one contact target. Here the stages come from
// what the object does, frame by frame: still, moved rigidly, or articulated (its hinge
// angle changes, the Art metric's test); runs shorter than `min_frames` join the run before.
// Each stage's contact target is the contact map of its middle frame, held over the stage.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <ATen/core/Tensor.h>

namespace bimart {

struct ManipulationStage {
  std::int64_t first = 0, last = 0;  // frames, inclusive
  int what = 0;                      // 0 still, 1 moved rigidly, 2 articulated
};

// states [N, 7] -> the stages, covering frames 0..N-1 in order.
std::vector<ManipulationStage> manipulation_stages(const at::Tensor& states, std::int64_t min_frames);

// C [S, N, 2, M] (or [N, 2, M]) -> the same shape, each stage's frames holding the map of its
// middle frame.
at::Tensor stage_contact_targets(const at::Tensor& maps, const std::vector<ManipulationStage>& stages);

// [K, 3] int64: first, last, what per stage (a stage output); and back.
at::Tensor stages_tensor(const std::vector<ManipulationStage>& stages);
std::vector<ManipulationStage> stages_from_tensor(const at::Tensor& t);

}  // namespace bimart
