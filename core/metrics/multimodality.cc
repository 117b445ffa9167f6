#include "core/metrics/multimodality.h"

#include <string>

#include <ATen/ATen.h>

#include "core/util/error.h"

namespace bimart {

double multimodality(const std::vector<at::Tensor>& samples) {
  if (samples.size() < 2)
    throw Error("Mul needs at least 2 samples of a trajectory, got " + std::to_string(samples.size()));
  std::vector<at::Tensor> v;
  for (const at::Tensor& s : samples) {
    if (!s.sizes().equals(samples[0].sizes()) || s.dim() != 4 || s.size(3) != 3)
      throw Error("Mul: every sample must have the same [2, N, V, 3] hand vertices");
    v.push_back(s.to(at::kCPU, at::kDouble));
  }
  double sum = 0;
  int64_t pairs = 0;
  for (size_t i = 0; i < v.size(); ++i)
    for (size_t j = i + 1; j < v.size(); ++j, ++pairs) sum += (v[i] - v[j]).norm(2, -1).mean().item<double>();
  return sum / static_cast<double>(pairs);
}

}  // namespace bimart
