// Accel (DESIGN §6): mean over frames t >= 2, both hands and all vertices of
// ||v_t - 2 v_{t-1} + v_{t-2}|| for one sequence, in m per frame² (× 100 for the table).
#pragma once

#include <ATen/core/Tensor.h>

namespace bimart {

// `vertices` [2, N, V, 3]; NaN when N < 3 (no second difference).
double mean_acceleration(const at::Tensor& vertices);

}  // namespace bimart
