#include "core/io/npz_tensor.h"

#include <ATen/ATen.h>

#include <cstring>

namespace bimart {
namespace {

struct DtypePair {
  at::ScalarType type;
  const char* code;
};
constexpr DtypePair kPairs[] = {{at::kFloat, "f4"}, {at::kDouble, "f8"}, {at::kLong, "i8"}, {at::kInt, "i4"},
                                {at::kByte, "u1"},  {at::kBool, "b1"},   {at::kHalf, "f2"}};

}  // namespace

NpyArray npy_from_tensor(const at::Tensor& t) {
  for (const auto& p : kPairs) {
    if (t.scalar_type() != p.type) continue;
    const at::Tensor c = t.detach().contiguous();
    NpyArray a{p.code, std::vector<int64_t>(c.sizes().begin(), c.sizes().end()), {}};
    a.data.resize(static_cast<size_t>(c.numel()) * c.element_size());
    if (!a.data.empty()) std::memcpy(a.data.data(), c.data_ptr(), a.data.size());
    return a;
  }
  throw Error(std::string("cannot store a tensor of type ") + c10::toString(t.scalar_type()) + " in a .npy array");
}

at::Tensor tensor_from_npy(const NpyArray& a, const std::string& what) {
  a.check(what);
  for (const auto& p : kPairs) {
    if (a.dtype != p.code) continue;
    at::Tensor t = at::empty(std::vector<int64_t>(a.shape.begin(), a.shape.end()), at::TensorOptions().dtype(p.type));
    if (!a.data.empty()) std::memcpy(t.data_ptr(), a.data.data(), a.data.size());
    return t;
  }
  throw Error(what + ": arrays of type '" + a.dtype + "' cannot become a tensor");
}

}  // namespace bimart
