// Linear blend skinning of a MANO-layout hand (core/hand/hand_model.h), templated on the
// scalar so that Ceres Jets differentiate it. For batches on tensors see lbs_torch.h.
//
// MANO's convention:
//   v_shaped = v_template + shapedirs · β
//   J        = J_regressor · v_shaped                       (rest joints, [16, 3])
//   feature  = concat over joints 1..15 of (R_j − I), row-major, 9 each  ([135])
//   v_posed  = v_shaped + posedirs · feature
//   G_j      = G_parent(j) · [R_j | J_j − J_parent(j)],  G_0 = [R_0 | J_0]
//   world v  = Σ_j w_vj · G_j · [I | −J_j] · [v_posed; 1] + trans
//   joint j  = translation of G_j + trans
// R_0 is the global rotation (about J_0), R_1..R_15 the finger pose; pose is "flat": zero
// is the flat hand, not MANO's mean pose (convert with the helpers at the end).
#pragma once

#include <cmath>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "core/hand/hand_model.h"
#include "core/util/error.h"

namespace bimart {

// The 21 keypoints: 16 joints, then the 5 fingertip vertices (thumb, index, middle, ring,
// pinky).
inline constexpr int kNumKeypoints21 = 21;

template <class T>
struct LbsResult {
  Eigen::Matrix<T, Eigen::Dynamic, 3, Eigen::RowMajor> vertices;  // [V, 3] metres
  Eigen::Matrix<T, HandModel::kNumJoints, 3, Eigen::RowMajor> joints;  // [16, 3] metres
};

// Axis-angle `aa` (3) to a row-major 3x3 rotation `R` (9). Exact at zero and smooth around
// it: tiny angles use the Taylor series, so Jet derivatives stay finite.
template <class T>
void axis_angle_to_matrix(const T* aa, T* R) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta2 = aa[0] * aa[0] + aa[1] * aa[1] + aa[2] * aa[2];
  T a, b;  // R = I + a·K + b·K², K = [aa]×
  if (theta2 > T(1e-8)) {
    const T theta = sqrt(theta2);
    a = sin(theta) / theta;
    b = (T(1) - cos(theta)) / theta2;
  } else {  // sin θ/θ and (1 − cos θ)/θ² to O(θ⁴), error below 1e-18
    a = T(1) - theta2 / T(6);
    b = T(0.5) - theta2 / T(24);
  }
  const T x = aa[0], y = aa[1], z = aa[2];
  // K² = aa·aaᵀ − θ² I
  R[0] = T(1) + b * (x * x - theta2);
  R[1] = -a * z + b * x * y;
  R[2] = a * y + b * x * z;
  R[3] = a * z + b * x * y;
  R[4] = T(1) + b * (y * y - theta2);
  R[5] = -a * x + b * y * z;
  R[6] = -a * y + b * x * z;
  R[7] = a * x + b * y * z;
  R[8] = T(1) + b * (z * z - theta2);
}

// The kinematic chain: local rotations R_j (row-major 3x3) and rest joints J_j give the
// global transforms G_j = [GR_j | Gt_j] and the skinning offsets At_j = Gt_j − GR_j·J_j.
// Shared by lbs() and lbs_subset() (core/hand/lbs_subset.h). TJ is T or double.
template <class T, class TJ>
void kinematic_chain(const std::array<int, HandModel::kNumJoints>& parents,
                     const T (&R)[HandModel::kNumJoints][9], const TJ (&J)[HandModel::kNumJoints][3],
                     T (&GR)[HandModel::kNumJoints][9], T (&Gt)[HandModel::kNumJoints][3],
                     T (&At)[HandModel::kNumJoints][3]) {
  for (int j = 0; j < HandModel::kNumJoints; ++j) {
    const int p = parents[j];
    if (p < 0) {
      for (int e = 0; e < 9; ++e) GR[j][e] = R[j][e];
      for (int k = 0; k < 3; ++k) Gt[j][k] = T(J[j][k]);
    } else {
      const TJ rel[3] = {J[j][0] - J[p][0], J[j][1] - J[p][1], J[j][2] - J[p][2]};
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c)
          GR[j][3 * r + c] = GR[p][3 * r] * R[j][c] + GR[p][3 * r + 1] * R[j][3 + c] +
                             GR[p][3 * r + 2] * R[j][6 + c];
        Gt[j][r] = GR[p][3 * r] * rel[0] + GR[p][3 * r + 1] * rel[1] + GR[p][3 * r + 2] * rel[2] +
                   Gt[p][r];
      }
    }
    for (int r = 0; r < 3; ++r)
      At[j][r] = Gt[j][r] - (GR[j][3 * r] * J[j][0] + GR[j][3 * r + 1] * J[j][1] +
                             GR[j][3 * r + 2] * J[j][2]);
  }
}

// Posed hand. rot (3): global axis-angle; pose (45): finger axis-angle, flat; trans (3);
// betas (10). Model matrices stay double; only the products with T are formed. The model
// must be valid (load_hand_model validates; call validate() on one built in code).
template <class T>
void lbs(const HandModel& m, const T* rot, const T* pose, const T* trans, const T* betas,
         LbsResult<T>* out) {
  constexpr int kJ = HandModel::kNumJoints;
  const int V = m.num_vertices();
  const int V3 = 3 * V;
  constexpr bool kPlain = std::is_floating_point_v<T>;

  // Shape blend shapes: column by column (column-major storage, contiguous).
  std::vector<T> v(V3);
  for (int i = 0; i < V; ++i)
    for (int k = 0; k < 3; ++k) v[3 * i + k] = T(m.v_template(i, k));
  for (int c = 0; c < HandModel::kNumBetas; ++c) {
    const double* col = m.shapedirs.col(c).data();
    const T bc = betas[c];
    for (int i = 0; i < V3; ++i) v[i] += col[i] * bc;
  }

  // Rest joints; J_regressor is mostly zeros in MANO, so skip them.
  T J[kJ][3];
  for (int j = 0; j < kJ; ++j) {
    J[j][0] = J[j][1] = J[j][2] = T(0);
    for (int i = 0; i < V; ++i) {
      const double w = m.j_regressor(j, i);
      if (w == 0.0) continue;
      for (int k = 0; k < 3; ++k) J[j][k] += w * v[3 * i + k];
    }
  }

  // Local rotations and the pose-corrective blend shapes.
  T R[kJ][9];
  axis_angle_to_matrix(rot, R[0]);
  for (int j = 1; j < kJ; ++j) axis_angle_to_matrix(pose + 3 * (j - 1), R[j]);
  for (int j = 1; j < kJ; ++j) {
    for (int e = 0; e < 9; ++e) {
      const T f = R[j][e] - T(e % 4 == 0 ? 1 : 0);  // (R − I), diagonal at 0, 4, 8
      if constexpr (kPlain) {
        if (f == T(0)) continue;
      }
      const double* col = m.posedirs.col(9 * (j - 1) + e).data();
      for (int i = 0; i < V3; ++i) v[i] += col[i] * f;
    }
  }

  // Global transforms G_j = [GR | Gt], then A_j = G_j · [I | −J_j] for skinning.
  T GR[kJ][9], Gt[kJ][3], At[kJ][3];
  kinematic_chain(m.parents, R, J, GR, Gt, At);

  // Skinning: blend the 3x4 transforms by weight (skipping zero weights), apply, translate.
  out->vertices.resize(V, 3);
  for (int i = 0; i < V; ++i) {
    T B[12];
    for (int e = 0; e < 12; ++e) B[e] = T(0);
    for (int j = 0; j < kJ; ++j) {
      const double w = m.weights(i, j);
      if (w == 0.0) continue;
      for (int e = 0; e < 9; ++e) B[e] += w * GR[j][e];
      for (int k = 0; k < 3; ++k) B[9 + k] += w * At[j][k];
    }
    const T* p = &v[3 * i];
    for (int r = 0; r < 3; ++r)
      out->vertices(i, r) = B[3 * r] * p[0] + B[3 * r + 1] * p[1] + B[3 * r + 2] * p[2] + B[9 + r] +
                            trans[r];
  }
  for (int j = 0; j < kJ; ++j)
    for (int r = 0; r < 3; ++r) out->joints(j, r) = Gt[j][r] + trans[r];
}

// Eigen-vector convenience form of lbs().
template <class T>
LbsResult<T> lbs(const HandModel& m, const Eigen::Matrix<T, 3, 1>& rot,
                 const Eigen::Matrix<T, Eigen::Dynamic, 1>& pose, const Eigen::Matrix<T, 3, 1>& trans,
                 const Eigen::Matrix<T, Eigen::Dynamic, 1>& betas) {
  if (pose.size() != HandModel::kPoseDim || betas.size() != HandModel::kNumBetas)
    throw Error("lbs: expected 45 pose and 10 shape values, got " + std::to_string(pose.size()) +
                " and " + std::to_string(betas.size()));
  LbsResult<T> out;
  lbs(m, rot.data(), pose.data(), trans.data(), betas.data(), &out);
  return out;
}

// The 21 keypoints [21, 3]: joints, then fingertip vertices (thumb, index, middle, ring, pinky).
template <class T>
Eigen::Matrix<T, kNumKeypoints21, 3, Eigen::RowMajor> keypoints21(const HandModel& m,
                                                                  const LbsResult<T>& r) {
  Eigen::Matrix<T, kNumKeypoints21, 3, Eigen::RowMajor> k;
  k.template topRows<HandModel::kNumJoints>() = r.joints;
  for (int i = 0; i < 5; ++i) k.row(HandModel::kNumJoints + i) = r.vertices.row(m.fingertips[i]);
  return k;
}

// ---- Finger pose conversions -------------------------------------------------------------
// MANO's files (and ARCTIC's data) give the finger pose relative to hands_mean, or as PCA
// coefficients: mean-relative pose = coeffs · hands_components[:n]; flat = that + hands_mean.

inline Eigen::VectorXd flat_pose_from_mean_relative(const HandModel& m, const Eigen::VectorXd& rel) {
  return rel + m.hands_mean;
}
inline Eigen::VectorXd mean_relative_from_flat_pose(const HandModel& m, const Eigen::VectorXd& flat) {
  return flat - m.hands_mean;
}
// n = coeffs.size() <= 45 leading components. Returns the flat pose.
Eigen::VectorXd flat_pose_from_pca(const HandModel& m, const Eigen::VectorXd& coeffs);
// Least-squares PCA coefficients (n leading components) of a flat pose; exact for n = 45.
Eigen::VectorXd pca_from_flat_pose(const HandModel& m, const Eigen::VectorXd& flat, int n);

}  // namespace bimart
