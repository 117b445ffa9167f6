#include "core/object/object_batch.h"

#include <ATen/ATen.h>

#include <string>

#include "core/util/error.h"

namespace bimart {

namespace {

at::Tensor to_tensor(const TriangleMesh& m, at::ScalarType dtype) {
  // The mesh stores rows of 3 doubles contiguously (RowMajor).
  at::Tensor v = at::from_blob(const_cast<double*>(m.vertices.data()), {m.num_vertices(), 3}, at::kDouble);
  return v.to(dtype);  // copies, so the mesh need not outlive the result
}

}  // namespace

at::Tensor axis_angle_to_matrix_batch(const at::Tensor& aa) {
  const int64_t n = aa.size(0);
  const at::Tensor theta2 = (aa * aa).sum(1);
  const at::Tensor small = theta2 < 1e-12;
  const at::Tensor theta = at::sqrt(at::where(small, at::ones_like(theta2), theta2));
  // a = sin t / t, b = (1 - cos t) / t^2, with Taylor terms where t is tiny.
  const at::Tensor a = at::where(small, 1.0 - theta2 / 6.0, at::sin(theta) / theta);
  const at::Tensor b = at::where(small, 0.5 - theta2 / 24.0, (1.0 - at::cos(theta)) / (theta * theta));
  const at::Tensor x = aa.select(1, 0), y = aa.select(1, 1), z = aa.select(1, 2);
  const at::Tensor zero = at::zeros_like(x);
  const at::Tensor K = at::stack({zero, -z, y, z, zero, -x, -y, x, zero}, 1).view({n, 3, 3});
  const at::Tensor eye = at::eye(3, aa.options()).expand({n, 3, 3});
  return eye + a.view({n, 1, 1}) * K + b.view({n, 1, 1}) * at::bmm(K, K);
}

PosedObjectBatch pose_object_batch(const ArticulatedObject& object, const at::Tensor& states) {
  if (states.dim() != 2 || states.size(1) != 7)
    throw Error("object states must be [N, 7], got " + std::string(c10::str(states.sizes())));
  if (states.scalar_type() != at::kFloat && states.scalar_type() != at::kDouble)
    throw Error("object states must be float32 or float64");
  if (!at::isfinite(states).all().item<bool>()) throw Error("object states hold a non-finite number");
  const at::ScalarType dtype = states.scalar_type();
  const int64_t n = states.size(0);
  const at::Tensor s = states.contiguous();

  // Hinge: rotation by angle about -z = rotation by -angle about +z.
  const at::Tensor angle = s.select(1, 0);
  const at::Tensor c = at::cos(angle), si = at::sin(angle);
  const at::Tensor zero = at::zeros_like(angle), one = at::ones_like(angle);
  const at::Tensor hinge = at::stack({c, si, zero, -si, c, zero, zero, zero, one}, 1).view({n, 3, 3});

  const at::Tensor root = axis_angle_to_matrix_batch(s.narrow(1, 1, 3));
  const at::Tensor trans = s.narrow(1, 4, 3).unsqueeze(1);  // [N, 1, 3]

  const at::Tensor top = to_tensor(object.top, dtype);
  const at::Tensor bottom = to_tensor(object.bottom, dtype);
  // Row vectors: v' = v R^T + t.
  const at::Tensor top_rot = at::bmm(root, hinge);
  PosedObjectBatch out;
  out.top = at::matmul(top.unsqueeze(0), top_rot.transpose(1, 2)) + trans;
  out.bottom = at::matmul(bottom.unsqueeze(0), root.transpose(1, 2)) + trans;
  return out;
}

at::Tensor canonical_to_world_batch(const at::Tensor& points, const at::Tensor& states) {
  const at::Tensor s = states.to(at::kDouble);
  const at::Tensor R = axis_angle_to_matrix_batch(s.narrow(1, 1, 3).contiguous());  // [N, 3, 3]
  return at::matmul(points.to(at::kDouble), R.transpose(1, 2)) + s.narrow(1, 4, 3).unsqueeze(1);
}

}  // namespace bimart
