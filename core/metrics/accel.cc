#include "core/metrics/accel.h"

#include <limits>

#include <ATen/ATen.h>

#include "core/util/error.h"

namespace bimart {

double mean_acceleration(const at::Tensor& vertices_in) {
  if (vertices_in.dim() != 4 || vertices_in.size(3) != 3) throw Error("hand vertices must be [2, N, V, 3]");
  const at::Tensor v = vertices_in.to(at::kCPU, at::kDouble);
  const int64_t n = v.size(1);
  if (n < 3 || v.size(2) == 0) return std::numeric_limits<double>::quiet_NaN();
  using at::indexing::Slice;
  const at::Tensor a = v.index({Slice(), Slice(2, n)}) - 2 * v.index({Slice(), Slice(1, n - 1)}) +
                       v.index({Slice(), Slice(0, n - 2)});
  return a.norm(2, -1).mean().item<double>();
}

}  // namespace bimart
