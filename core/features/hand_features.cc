#include "core/features/hand_features.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include <string>

#include "core/geometry/nearest_points.h"
#include "core/object/object_state.h"
#include "core/util/error.h"

namespace bimart {

namespace {

std::string shape(const at::Tensor& t) { return t.defined() ? std::string(c10::str(t.sizes())) : "undefined"; }

std::vector<ObjectState> read_states(const at::Tensor& states, int64_t n) {
  if (states.dim() != 2 || states.size(1) != 7 || states.size(0) != n)
    throw Error("object_states must be [N, 7] with N = " + std::to_string(n) + ", got " + shape(states));
  const at::Tensor st = states.to(at::kDouble).contiguous();
  std::vector<ObjectState> out(n);
  for (int64_t t = 0; t < n; ++t) out[t] = ObjectState::from_row(st.data_ptr<double>() + 7 * t);
  return out;
}

}  // namespace

at::Tensor hand_features(const at::Tensor& hand_vertices_world, const std::vector<int>& keypoint_ids,
                         const ArticulatedObject& object, const at::Tensor& states) {
  const at::Tensor& hv = hand_vertices_world;
  if (hv.dim() != 4 || hv.size(0) != 2 || hv.size(3) != 3)
    throw Error("hand vertices must be [2, N, V, 3], got " + shape(hv));
  if (static_cast<int>(keypoint_ids.size()) != kHandKeypoints)
    throw Error("hand features need " + std::to_string(kHandKeypoints) + " keypoint ids, got " +
                std::to_string(keypoint_ids.size()));
  const int64_t n = hv.size(1), v = hv.size(2);
  for (int id : keypoint_ids)
    if (id < 0 || id >= v)
      throw Error("keypoint id " + std::to_string(id) + " is not one of the " + std::to_string(v) + " hand vertices");
  const std::vector<ObjectState> st = read_states(states, n);
  if (object.top.num_vertices() == 0 || object.bottom.num_vertices() == 0)
    throw Error("object '" + object.name + "' has an empty part");

  // Parts are rigid: one tree each in the part's own frame; keypoints move into it.
  const NearestPoints top(object.top.vertices), bottom(object.bottom.vertices);
  const at::Tensor vd = hv.to(at::kDouble).contiguous();
  const double* V = vd.data_ptr<double>();
  at::Tensor out = at::empty({n, kHandFeatureSize}, at::kFloat);
  float* X = out.data_ptr<float>();
  constexpr int J = kHandKeypoints;
  at::parallel_for(0, n, 1, [&](int64_t begin, int64_t end) {
    for (int64_t t = begin; t < end; ++t) {
      const Eigen::Isometry3d world_to_canonical = canonical_to_world(st[t]).inverse();
      const Eigen::Matrix3d R_top = top_to_canonical(st[t].angle).linear();
      for (int h = 0; h < 2; ++h) {
        float* H = X + t * kHandFeatureSize + h * 3 * J;
        float* D = H + 6 * J;
        for (int j = 0; j < J; ++j) {
          const double* p = V + ((h * n + t) * v + keypoint_ids[j]) * 3;
          const Eigen::Vector3d pc = world_to_canonical * Eigen::Vector3d(p[0], p[1], p[2]);
          const NearestPoints::Hit ht = top.nearest(R_top.transpose() * pc);
          const NearestPoints::Hit hb = bottom.nearest(pc);
          const Eigen::Vector3d nearest = ht.distance_sq <= hb.distance_sq
                                              ? Eigen::Vector3d(R_top * top.points().row(ht.index).transpose())
                                              : Eigen::Vector3d(bottom.points().row(hb.index).transpose());
          const Eigen::Vector3d d = nearest - pc;
          for (int c = 0; c < 3; ++c) {
            H[3 * j + c] = static_cast<float>(pc[c]);
            D[3 * j + c] = static_cast<float>(d[c]);
          }
        }
      }
    }
  });
  return out;
}

std::pair<at::Tensor, at::Tensor> split_hand_features(const at::Tensor& features) {
  if (features.dim() != 2 || features.size(1) != kHandFeatureSize)
    throw Error("hand features X must be [N, " + std::to_string(kHandFeatureSize) + "], got " + shape(features));
  const int64_t n = features.size(0);
  // [N, 4, J, 3] in the order H_left, H_right, D_left, D_right.
  const at::Tensor blocks = features.reshape({n, 4, kHandKeypoints, 3});
  return {blocks.slice(1, 0, 2).transpose(0, 1), blocks.slice(1, 2, 4).transpose(0, 1)};
}

at::Tensor join_hand_features(const at::Tensor& positions, const at::Tensor& directions) {
  if (positions.dim() != 4 || positions.size(0) != 2 || positions.size(2) != kHandKeypoints ||
      positions.size(3) != 3 || !directions.sizes().equals(positions.sizes()))
    throw Error("hand keypoints and directions must both be [2, N, " + std::to_string(kHandKeypoints) +
                ", 3], got " + shape(positions) + " and " + shape(directions));
  const int64_t n = positions.size(1);
  return at::cat({positions.transpose(0, 1), directions.transpose(0, 1)}, 1).reshape({n, kHandFeatureSize});
}

HandKeypointsWorld hand_features_to_world(const at::Tensor& features, const at::Tensor& states) {
  auto [h, d] = split_hand_features(features);
  const int64_t n = features.size(0);
  const std::vector<ObjectState> st = read_states(states, n);
  at::Tensor R = at::empty({n, 3, 3}, at::kDouble), t = at::empty({n, 1, 3}, at::kDouble);
  for (int64_t i = 0; i < n; ++i) {
    const Eigen::Isometry3d T = canonical_to_world(st[i]);
    for (int r = 0; r < 3; ++r) {
      t[i][0][r] = T.translation()[r];
      for (int c = 0; c < 3; ++c) R[i][r][c] = T.linear()(r, c);
    }
  }
  R = R.to(features.scalar_type());
  t = t.to(features.scalar_type());
  // Rows are points: p_world = p R^T + t, per frame (broadcast over hands and keypoints).
  const at::Tensor Rt = R.transpose(1, 2).unsqueeze(0);  // [1, N, 3, 3]
  return {at::matmul(h, Rt) + t.unsqueeze(0), at::matmul(d, Rt)};
}

}  // namespace bimart
