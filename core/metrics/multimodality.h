// Mul (DESIGN §6): for one trajectory with S >= 2 generated samples, the mean over sample
// pairs (i < j) of the mean per-vertex distance between the two samples' hand vertices
// (both hands, all frames), in metres (× 100 for the table); averaged over trajectories.
#pragma once

#include <vector>

#include <ATen/core/Tensor.h>

namespace bimart {

// `samples`: S tensors [2, N, V, 3] of one trajectory. Throws bimart::Error when S < 2 or
// the shapes differ.
double multimodality(const std::vector<at::Tensor>& samples);

}  // namespace bimart
