// libtorch tensors to and from .npy arrays (core/io/npz.h), keeping the element type:
// float32 <-> f4, float64 <-> f8, int64 <-> i8, int32 <-> i4, uint8 <-> u1, bool <-> b1, float16 <-> f2.
#pragma once

#include <string>

#include <ATen/core/Tensor.h>

#include "core/io/npz.h"

namespace bimart {

// Any of the types above, any shape; copies. Throws bimart::Error for another dtype.
NpyArray npy_from_tensor(const at::Tensor& t);
// A tensor of the array's type and shape; throws bimart::Error naming `what` for a string or
// unsupported dtype.
at::Tensor tensor_from_npy(const NpyArray& a, const std::string& what);

}  // namespace bimart
