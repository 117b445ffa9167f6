// Refining every sample of a generator's batch (the contract in stages/refiner.h): the
// samples run in parallel (core/util/parallel.h), each on one thread; a single sample gets
// all the threads (its two hands run in parallel).
#pragma once

#include <ATen/ATen.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "core/hand/hand_motion.h"
#include "core/pipeline/stage.h"
#include "core/util/error.h"
#include "core/util/parallel.h"

namespace bimart::refine_plugin {

// Refines sample `k` from keypoints X [N, 1200], optionally starting from `start`, on
// `threads` threads (0: the stage's own setting).
using RefineOne = std::function<HandMotion(std::size_t k, const at::Tensor& X, const HandMotion* start, int threads)>;

// Reads the keypoints (and starts) of every sample, refines them and writes `hand_params`
// (sample 0) and `hand_samples`. `threads`: the stage's parameter (0: all cores).
inline void refine_samples(StageIO& io, int threads, const RefineOne& refine_one) {
  const at::Tensor& X = io.in<at::Tensor>("hand_keypoints");
  std::vector<at::Tensor> keypoints;
  if (io.has("hand_keypoints_samples")) {
    const at::Tensor& batch = io.in<at::Tensor>("hand_keypoints_samples");
    if (batch.dim() != 3 || batch.size(0) < 1 || batch.size(1) != X.size(0) || batch.size(2) != X.size(1))
      throw Error("hand_keypoints_samples must be [S, " + std::to_string(X.size(0)) + ", " +
                  std::to_string(X.size(1)) + "] like hand_keypoints, got [" +
                  fmt::format("{}", fmt::join(batch.sizes(), ", ")) + "]");
    if (!at::equal(batch[0], X))
      throw Error("hand_keypoints is not sample 0 of hand_keypoints_samples: wire both from the same stage");
    for (std::int64_t k = 0; k < batch.size(0); ++k) keypoints.push_back(batch[k].contiguous());
  } else {
    keypoints.push_back(X);
  }
  const std::size_t S = keypoints.size();
  std::vector<const HandMotion*> starts(S, nullptr);
  if (io.has("hand_samples")) {
    const auto& given = io.in<std::vector<HandMotion>>("hand_samples");
    if (given.size() != S)
      throw Error("hand_samples holds " + std::to_string(given.size()) + " motions to start from, but there are " +
                  std::to_string(S) + " samples of keypoints");
    for (std::size_t k = 0; k < S; ++k) starts[k] = &given[k];
  } else if (io.has("hand_params") && S == 1) {
    starts[0] = &io.in<HandMotion>("hand_params");
  } else if (io.has("hand_params")) {
    throw Error("hand_params is one motion, but there are " + std::to_string(S) +
                " samples: wire the previous refiner's hand_samples too");
  }
  std::vector<HandMotion> out(S);
  if (S == 1) {
    out[0] = refine_one(0, keypoints[0], starts[0], threads);
  } else {
    const int outer = std::min<int>(static_cast<int>(S), resolve_threads(threads));
    parallel_for(S, outer, [&](std::size_t k) { out[k] = refine_one(k, keypoints[k], starts[k], 1); });
  }
  io.out("hand_params", out[0]);
  io.out("hand_samples", std::move(out));
}

}  // namespace bimart::refine_plugin
