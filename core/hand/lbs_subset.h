// Linear blend skinning of a chosen subset of a hand's vertices (the 100 keypoints, the
// vertices near an object), templated like lbs() (core/hand/lbs.h) so that Ceres Jets
// differentiate it, at a cost in proportion to the subset: the rest joints are
// precomputed as linear in β (J = J_template + J_shapedirs·β, exact because the
// regressor acts on the shaped mesh before posing).
//
// With Jets, the blend shapes — the bulk of the work — skip the derivative entries their
// coefficients do not carry (β carries its own 10; each joint's 9 pose features its own 3
// pose values), several times cheaper than plain Jet arithmetic.
// lbs() stays the reference; tests/hand/lbs_subset_test.cc holds the two equal.
#pragma once

#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/hand/hand_model.h"
#include "core/hand/lbs.h"

namespace bimart {

struct LbsSubset {
  std::vector<int> vertex_ids;  // rows of the full model, in this order
  // Row-major so that one vertex coordinate's blend shapes are contiguous.
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> v_template;  // [S, 3]
  Eigen::Matrix<double, Eigen::Dynamic, HandModel::kNumBetas, Eigen::RowMajor> shapedirs;  // [3S, 10]
  Eigen::Matrix<double, Eigen::Dynamic, HandModel::kNumPoseFeatures, Eigen::RowMajor> posedirs;  // [3S, 135]
  // Skinning weights, sparse: vertex s uses joints weight_joint[k] with weight_value[k]
  // for k in [weight_start[s], weight_start[s + 1]).
  std::vector<int> weight_start, weight_joint;
  std::vector<double> weight_value;
  Eigen::Matrix<double, HandModel::kNumJoints, 3, Eigen::RowMajor> j_template;  // [16, 3]
  Eigen::Matrix<double, 3 * HandModel::kNumJoints, HandModel::kNumBetas, Eigen::RowMajor> j_shapedirs;  // [48, 10]
  std::array<int, HandModel::kNumJoints> parents{};
  bool has_pose_correctives = true;  // false when posedirs is all zero (the procedural hand)

  int size() const { return static_cast<int>(vertex_ids.size()); }
  // Throws bimart::Error for an id out of range. The model must be valid.
  static LbsSubset from(const HandModel& model, const std::vector<int>& vertex_ids);
};

namespace lbs_detail {
template <class T, class = void>
struct IsJet : std::false_type {};
template <class T>
struct IsJet<T, std::void_t<decltype(std::declval<T>().a), decltype(std::declval<T>().v)>>
    : std::true_type {};

// out[i] += Σ_k A[i·lda + k] · c[k] for i < rows, k < K. With Jets, only the derivative
// entries that some c[k] carries are accumulated (β and each joint's features carry few).
template <class T, class TC>
void add_product(const double* A, int lda, int rows, int K, const TC* c, T* out) {
  if constexpr (IsJet<TC>::value) {
    constexpr int N = decltype(std::declval<TC>().v)::RowsAtCompileTime;
    int nz[N];
    int n_nz = 0;
    for (int d = 0; d < N; ++d) {
      bool any = false;
      for (int k = 0; k < K && !any; ++k) any = c[k].v[d] != 0.0;
      if (any) nz[n_nz++] = d;
    }
    for (int i = 0; i < rows; ++i) {
      const double* a = A + static_cast<std::ptrdiff_t>(i) * lda;
      double val = 0;
      for (int k = 0; k < K; ++k) val += a[k] * c[k].a;
      out[i].a += val;
      for (int q = 0; q < n_nz; ++q) {
        const int d = nz[q];
        double g = 0;
        for (int k = 0; k < K; ++k) g += a[k] * c[k].v[d];
        out[i].v[d] += g;
      }
    }
  } else {
    for (int i = 0; i < rows; ++i) {
      const double* a = A + static_cast<std::ptrdiff_t>(i) * lda;
      TC val = TC(0);
      for (int k = 0; k < K; ++k) val += a[k] * c[k];
      out[i] += val;
    }
  }
}
// Jets whose derivative entries fit a 64-bit mask.
template <class T, class = void>
struct IsSmallJet : std::false_type {};
template <class T>
struct IsSmallJet<T, std::enable_if_t<IsJet<T>::value>>
    : std::bool_constant<(decltype(std::declval<T>().v)::RowsAtCompileTime <= 64)> {};

// Bit d set when some value carries derivative entry d (Jets with at most 64 entries).
template <class T>
std::uint64_t derivative_mask(const T* x, int n) {
  constexpr int N = decltype(std::declval<T>().v)::RowsAtCompileTime;
  std::uint64_t mask = 0;
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < N; ++d)
      if (x[i].v[d] != 0.0) mask |= std::uint64_t{1} << d;
  return mask;
}

// Skinning: out[3s + r] = (Σ_j w_sj [GR_j | At_j]) · [p_s; 1] + trans, p = v[3s..3s+2]
// of type TV (T or plain). With Jets of up to 64 entries, each vertex works on the entries
// its joints, p and trans carry only (a fingertip's: rot, its finger's 9 pose values and
// trans — 15 of 51).
template <class T, class TV>
void skin(const LbsSubset& m, const T (&GR)[HandModel::kNumJoints][9], const T (&At)[HandModel::kNumJoints][3],
          const TV* v, const T* trans, T* out) {
  constexpr int kJ = HandModel::kNumJoints;
  const int S = m.size();
  if constexpr (IsSmallJet<T>::value) {
    std::uint64_t joint_mask[kJ];
    for (int j = 0; j < kJ; ++j) joint_mask[j] = derivative_mask(GR[j], 9) | derivative_mask(At[j], 3);
    const std::uint64_t trans_mask = derivative_mask(trans, 3);
    std::uint64_t v_mask = 0;
    if constexpr (IsJet<TV>::value) v_mask = derivative_mask(v, 3 * S);
    for (int s = 0; s < S; ++s) {
      double Ba[12] = {0};
      std::uint64_t mask = trans_mask | v_mask;
      for (int k = m.weight_start[s]; k < m.weight_start[s + 1]; ++k) {
        const int j = m.weight_joint[k];
        const double w = m.weight_value[k];
        for (int e = 0; e < 9; ++e) Ba[e] += w * GR[j][e].a;
        for (int r = 0; r < 3; ++r) Ba[9 + r] += w * At[j][r].a;
        mask |= joint_mask[j];
      }
      const TV* p = v + 3 * s;
      double pa[3];
      for (int c = 0; c < 3; ++c) {
        if constexpr (IsJet<TV>::value) pa[c] = p[c].a;
        else pa[c] = p[c];
      }
      T* o = out + 3 * s;
      for (int r = 0; r < 3; ++r) {
        o[r] = T(0);
        o[r].a = Ba[3 * r] * pa[0] + Ba[3 * r + 1] * pa[1] + Ba[3 * r + 2] * pa[2] + Ba[9 + r] + trans[r].a;
      }
      for (std::uint64_t rest = mask; rest; rest &= rest - 1) {
        const int d = __builtin_ctzll(rest);
        double Bd[12] = {0};
        for (int k = m.weight_start[s]; k < m.weight_start[s + 1]; ++k) {
          const int j = m.weight_joint[k];
          if (!(joint_mask[j] >> d & 1)) continue;
          const double w = m.weight_value[k];
          for (int e = 0; e < 9; ++e) Bd[e] += w * GR[j][e].v[d];
          for (int r = 0; r < 3; ++r) Bd[9 + r] += w * At[j][r].v[d];
        }
        for (int r = 0; r < 3; ++r) {
          double g = Bd[3 * r] * pa[0] + Bd[3 * r + 1] * pa[1] + Bd[3 * r + 2] * pa[2] + Bd[9 + r] + trans[r].v[d];
          if constexpr (IsJet<TV>::value)
            g += Ba[3 * r] * p[0].v[d] + Ba[3 * r + 1] * p[1].v[d] + Ba[3 * r + 2] * p[2].v[d];
          o[r].v[d] = g;
        }
      }
    }
  } else {
    for (int s = 0; s < S; ++s) {
      T B[12];
      for (int e = 0; e < 12; ++e) B[e] = T(0);
      for (int k = m.weight_start[s]; k < m.weight_start[s + 1]; ++k) {
        const int j = m.weight_joint[k];
        const double w = m.weight_value[k];
        for (int e = 0; e < 9; ++e) B[e] += w * GR[j][e];
        for (int r = 0; r < 3; ++r) B[9 + r] += w * At[j][r];
      }
      const TV* p = v + 3 * s;
      for (int r = 0; r < 3; ++r)
        out[3 * s + r] = B[3 * r] * p[0] + B[3 * r + 1] * p[1] + B[3 * r + 2] * p[2] + B[9 + r] + trans[r];
    }
  }
}
}  // namespace lbs_detail

// Posed subset vertices `out` [3S] (x, y, z per vertex, metres) and, if `joints` is not
// null, the 16 joints [48]. rot (3), pose (45, flat), trans (3) have scalar T; betas (10)
// may be T or double (a fixed shape keeps the joints free of derivatives).
template <class T, class TB>
void lbs_subset(const LbsSubset& m, const T* rot, const T* pose, const T* trans, const TB* betas,
                T* out, T* joints = nullptr) {
  constexpr int kJ = HandModel::kNumJoints;
  constexpr int kB = HandModel::kNumBetas;
  constexpr int kF = HandModel::kNumPoseFeatures;
  const int S = m.size();
  const int S3 = 3 * S;

  // Rest joints from β.
  TB J[kJ][3];
  for (int j = 0; j < kJ; ++j)
    for (int k = 0; k < 3; ++k) {
      TB x = TB(m.j_template(j, k));
      const double* row = m.j_shapedirs.row(3 * j + k).data();
      for (int c = 0; c < kB; ++c) x += row[c] * betas[c];
      J[j][k] = x;
    }

  // Local rotations and the pose features (R_j − I), 9 per finger joint.
  T R[kJ][9];
  axis_angle_to_matrix(rot, R[0]);
  for (int j = 1; j < kJ; ++j) axis_angle_to_matrix(pose + 3 * (j - 1), R[j]);
  T f[kF];
  for (int j = 1; j < kJ; ++j)
    for (int e = 0; e < 9; ++e) f[9 * (j - 1) + e] = R[j][e] - T(e % 4 == 0 ? 1 : 0);

  T GR[kJ][9], Gt[kJ][3], At[kJ][3];
  kinematic_chain(m.parents, R, J, GR, Gt, At);

  // Shaped and pose-corrected subset vertices, v [3S]: of type TB while no pose corrective
  // adds derivatives (a fixed β keeps them plain numbers).
  auto shaped = [&](auto zero) {
    std::vector<decltype(zero)> v(S3);
    for (int i = 0; i < S3; ++i) v[i] = decltype(zero)(m.v_template(i / 3, i % 3));
    lbs_detail::add_product(m.shapedirs.data(), kB, S3, kB, betas, v.data());
    return v;
  };
  if (m.has_pose_correctives) {
    std::vector<T> v = shaped(T(0));
    for (int j = 0; j < kJ - 1; ++j)
      lbs_detail::add_product(m.posedirs.data() + 9 * j, kF, S3, 9, f + 9 * j, v.data());
    lbs_detail::skin(m, GR, At, v.data(), trans, out);
  } else {
    const std::vector<TB> v = shaped(TB(0));
    lbs_detail::skin(m, GR, At, v.data(), trans, out);
  }
  if (joints)
    for (int j = 0; j < kJ; ++j)
      for (int r = 0; r < 3; ++r) joints[3 * j + r] = Gt[j][r] + trans[r];
}

}  // namespace bimart
