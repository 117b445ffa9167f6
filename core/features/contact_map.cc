#include "core/features/contact_map.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include <string>

#include "core/geometry/nearest_points.h"
#include "core/object/object_batch.h"
#include "core/object/object_state.h"
#include "core/util/error.h"

namespace bimart {

namespace {

std::string shape(const at::Tensor& t) { return t.defined() ? std::string(c10::str(t.sizes())) : "undefined"; }

// The independent implementation: all pairwise distances (cdist without the matmul
// shortcut, whose cancellation costs ~0.1 mm near contact in float32), minimum over hand
// points. Slow (seconds for 64 frames of meshes); tests use it to check the fast path.
at::Tensor contact_maps_pairwise(const at::Tensor& obj, const at::Tensor& hands) {
  std::vector<at::Tensor> per_hand;
  for (int h = 0; h < 2; ++h)
    per_hand.push_back(std::get<0>(at::cdist(obj, hands[h], 2.0, /*compute_mode=*/2).min(2)));
  return at::stack(per_hand, 1);  // [N, 2, K]
}

// Index of the nearest hand point for every object point: [N, 2, K] int64. One k-d tree
// per frame and hand over the hand points (a few hundred), frames in parallel.
at::Tensor nearest_hand_points(const at::Tensor& obj, const at::Tensor& hands) {
  const int64_t n = obj.size(0), k = obj.size(1), p = hands.size(2);
  const at::Tensor o = obj.detach().to(at::kDouble).contiguous();
  const at::Tensor hd = hands.detach().to(at::kDouble).contiguous();
  at::Tensor out = at::empty({n, 2, k}, at::kLong);
  const double* O = o.data_ptr<double>();
  const double* Hd = hd.data_ptr<double>();
  int64_t* I = out.data_ptr<int64_t>();
  at::parallel_for(0, n, 1, [&](int64_t begin, int64_t end) {
    std::vector<int> idx(k);
    std::vector<double> d2(k);
    for (int64_t t = begin; t < end; ++t) {
      const Points3 queries = Eigen::Map<const Points3>(O + t * k * 3, k, 3);
      for (int h = 0; h < 2; ++h) {
        NearestPoints tree(Eigen::Map<const Points3>(Hd + (h * n + t) * p * 3, p, 3));
        tree.nearest(queries, idx.data(), d2.data());
        std::copy(idx.begin(), idx.end(), I + (t * 2 + h) * k);
      }
    }
  });
  return out;
}

}  // namespace

at::Tensor basis_hit_points(const ArticulatedObject& object, const at::Tensor& states,
                            const at::Tensor& hit_indices) {
  if (states.dim() != 2 || states.size(1) != 7) throw Error("object_states must be [N, 7], got " + shape(states));
  if (hit_indices.dim() != 2 || hit_indices.size(0) != states.size(0))
    throw Error("basis_hit_indices must be [N, K] with N = " + std::to_string(states.size(0)) + ", got " +
                shape(hit_indices));
  const int64_t n = states.size(0), k = hit_indices.size(1);
  const int64_t vt = object.top.num_vertices(), vb = object.bottom.num_vertices();
  const at::Tensor st = states.to(at::kDouble).contiguous();
  const at::Tensor hi = hit_indices.to(at::kLong).contiguous();
  const auto S = st.accessor<double, 2>();
  const auto I = hi.accessor<int64_t, 2>();
  at::Tensor out = at::empty({n, k, 3}, at::kFloat);
  auto P = out.accessor<float, 3>();
  for (int64_t t = 0; t < n; ++t) {
    const Eigen::Matrix3d R = top_to_canonical(S[t][0]).linear();
    for (int64_t i = 0; i < k; ++i) {
      const int64_t v = I[t][i];
      if (v < 0 || v >= vt + vb)
        throw Error("basis_hit_indices[" + std::to_string(t) + "][" + std::to_string(i) + "] = " +
                    std::to_string(v) + " is not a vertex of '" + object.name + "' (" +
                    std::to_string(vt + vb) + " vertices)");
      const Eigen::Vector3d x = v < vt ? Eigen::Vector3d(R * object.top.vertices.row(v).transpose())
                                       : Eigen::Vector3d(object.bottom.vertices.row(v - vt).transpose());
      for (int c = 0; c < 3; ++c) P[t][i][c] = static_cast<float>(x[c]);
    }
  }
  return out;
}

at::Tensor contact_maps(const at::Tensor& object_points, const at::Tensor& hand_points) {
  if (object_points.dim() != 3 || object_points.size(2) != 3)
    throw Error("contact maps: object points must be [N, K, 3], got " + shape(object_points));
  if (hand_points.dim() != 4 || hand_points.size(0) != 2 || hand_points.size(1) != object_points.size(0) ||
      hand_points.size(3) != 3 || hand_points.size(2) == 0)
    throw Error("contact maps: hand points must be [2, N, P, 3] with N = " +
                std::to_string(object_points.size(0)) + ", got " + shape(hand_points));
  const at::Tensor hands = hand_points.to(object_points.scalar_type());
  // The nearest pairs come from k-d trees; their distances are then formed with libtorch,
  // so gradients reach both arguments exactly as through a minimum over all pairs.
  const int64_t n = object_points.size(0), k = object_points.size(1), p = hands.size(2);
  const at::Tensor idx = nearest_hand_points(object_points, hands);              // [N, 2, K]
  const at::Tensor flat = hands.permute({1, 0, 2, 3}).reshape({n, 2 * p, 3});     // [N, 2P, 3]
  const at::Tensor offset = at::arange(2, at::kLong).mul(p).view({1, 2, 1});
  const at::Tensor picked = flat.gather(1, (idx + offset).view({n, 2 * k, 1}).expand({n, 2 * k, 3}));
  return (object_points.unsqueeze(1) - picked.view({n, 2, k, 3})).norm(2, -1);
}

at::Tensor contact_maps_exhaustive(const at::Tensor& object_points, const at::Tensor& hand_points) {
  return contact_maps_pairwise(object_points, hand_points.to(object_points.scalar_type()));
}

at::Tensor world_contact_maps(const ArticulatedObject& object, const at::Tensor& states, const at::Tensor& hit_indices,
                              const at::Tensor& world_hand_points) {
  // basis_hit_points validates the shapes.
  return contact_maps(canonical_to_world_batch(basis_hit_points(object, states, hit_indices), states), world_hand_points);
}

}  // namespace bimart
