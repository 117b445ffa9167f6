#include "core/hand/lbs_torch.h"

#include <algorithm>
#include <string>
#include <vector>

#include <ATen/ATen.h>

#include "core/util/error.h"

namespace bimart {
namespace {

constexpr int kJ = HandModel::kNumJoints;

at::Tensor to_tensor(const Eigen::MatrixXd& m, at::ScalarType dtype) {
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rm = m;
  return at::from_blob(const_cast<double*>(rm.data()), {rm.rows(), rm.cols()}, at::kDouble)
      .to(dtype)
      .clone();
}

std::string shape_of(const at::Tensor& t) {
  if (!t.defined()) return "undefined";
  std::string s = "[";
  for (int64_t i = 0; i < t.dim(); ++i) s += (i ? ", " : "") + std::to_string(t.size(i));
  return s + "]";
}

void check_input(const at::Tensor& t, const char* name, int64_t B, int64_t n, at::ScalarType dtype) {
  if (!t.defined() || t.dim() != 2 || t.size(0) != B || t.size(1) != n)
    throw Error(std::string("lbs: ") + name + " must be [" + std::to_string(B) + ", " +
                std::to_string(n) + "], got " + shape_of(t));
  if (t.scalar_type() != dtype)
    throw Error(std::string("lbs: ") + name + " has dtype " + c10::toString(t.scalar_type()) +
                ", the model " + c10::toString(dtype));
}

}  // namespace

HandModelTensors HandModelTensors::from(const HandModel& m, at::ScalarType dtype) {
  if (dtype != at::kFloat && dtype != at::kDouble)
    throw Error("HandModelTensors: dtype must be float32 or float64");
  m.validate();
  const Eigen::Index V = m.num_vertices();
  HandModelTensors t;
  t.v_template = to_tensor(m.v_template, dtype);
  t.v_template_cm = to_tensor(m.v_template.transpose(), dtype).reshape({3 * V});
  // Row 3v+k of shapedirs/posedirs becomes column k·V + v.
  Eigen::MatrixXd blend(HandModel::kNumBetas + HandModel::kNumPoseFeatures, 3 * V);
  for (Eigen::Index v = 0; v < V; ++v)
    for (int k = 0; k < 3; ++k) {
      blend.col(k * V + v).head(HandModel::kNumBetas) = m.shapedirs.row(3 * v + k).transpose();
      blend.col(k * V + v).tail(HandModel::kNumPoseFeatures) = m.posedirs.row(3 * v + k).transpose();
    }
  t.blend_dirs = to_tensor(blend, dtype);
  const Eigen::MatrixXd jt = m.j_regressor * m.v_template;  // [16, 3]
  Eigen::MatrixXd js(HandModel::kNumBetas, 3 * kJ);          // [10, 48]
  for (int l = 0; l < HandModel::kNumBetas; ++l) {
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> d(
        m.shapedirs.col(l).data(), V, 3);
    const Eigen::Matrix<double, kJ, 3, Eigen::RowMajor> jd = m.j_regressor * d;
    js.row(l) = Eigen::Map<const Eigen::RowVectorXd>(jd.data(), 3 * kJ);
  }
  t.j_template = to_tensor(jt, dtype);
  t.j_shapedirs = to_tensor(js, dtype);
  t.weights_t = to_tensor(m.weights.transpose(), dtype);
  t.fingertips = at::tensor(std::vector<int64_t>(m.fingertips.begin(), m.fingertips.end()), at::kLong);
  t.hands_mean = to_tensor(m.hands_mean, dtype).view({-1});
  t.hands_components = to_tensor(m.hands_components, dtype);
  t.parents = m.parents;
  return t;
}

at::Tensor axis_angle_to_matrix(const at::Tensor& aa) {
  // R = I + a·K + b·K², K = [aa]×, K² = aa·aaᵀ − θ² I; Taylor series for tiny θ.
  const at::Tensor theta2 = (aa * aa).sum(-1, /*keepdim=*/true);  // [..., 1]
  const at::Tensor small = theta2 < 1e-8;
  const at::Tensor safe = at::where(small, at::ones_like(theta2), theta2);
  const at::Tensor theta = at::sqrt(safe);
  const at::Tensor a = at::where(small, 1 - theta2 / 6, at::sin(theta) / theta).unsqueeze(-1);
  const at::Tensor b = at::where(small, 0.5 - theta2 / 24, (1 - at::cos(theta)) / safe).unsqueeze(-1);
  const auto xyz = aa.unbind(-1);
  const at::Tensor zero = at::zeros_like(xyz[0]);
  std::vector<int64_t> shape = aa.sizes().vec();
  shape.back() = 3;
  shape.push_back(3);
  const at::Tensor K = at::stack({zero, -xyz[2], xyz[1], xyz[2], zero, -xyz[0], -xyz[1], xyz[0], zero}, -1)
                           .view(shape);
  const at::Tensor eye = at::eye(3, aa.options());
  const at::Tensor K2 = aa.unsqueeze(-1) * aa.unsqueeze(-2) - theta2.unsqueeze(-1) * eye;
  return eye + a * K + b * K2;
}

LbsTensors lbs(const HandModelTensors& m, const at::Tensor& rot, const at::Tensor& pose,
               const at::Tensor& trans, const at::Tensor& betas) {
  const at::ScalarType dtype = m.dtype();
  if (!rot.defined() || rot.dim() != 2) throw Error("lbs: rot must be [B, 3], got " + shape_of(rot));
  const int64_t B = rot.size(0);
  check_input(rot, "rot", B, 3, dtype);
  check_input(pose, "pose", B, HandModel::kPoseDim, dtype);
  check_input(trans, "trans", B, 3, dtype);
  check_input(betas, "betas", B, HandModel::kNumBetas, dtype);
  const int64_t V = m.num_vertices();

  const at::Tensor R = axis_angle_to_matrix(at::cat({rot.unsqueeze(1), pose.view({B, kJ - 1, 3})}, 1));
  const at::Tensor J = m.j_template + at::matmul(betas, m.j_shapedirs).view({B, kJ, 3});
  const at::Tensor eye = at::eye(3, rot.options());
  const at::Tensor feature = (R.slice(1, 1) - eye).reshape({B, HandModel::kNumPoseFeatures});
  // Shape and pose blend shapes in one product; [B, 3, V] coordinate-major.
  const at::Tensor v_posed =
      at::addmm(m.v_template_cm, at::cat({betas, feature}, 1), m.blend_dirs).view({B, 3, V});

  // Forward kinematics, one tree level at a time (MANO: wrist, then 3 levels of 5 joints).
  std::array<int, kJ> depth{};
  int max_depth = 0;
  for (int j = 1; j < kJ; ++j) max_depth = std::max(max_depth, depth[j] = depth[m.parents[j]] + 1);
  std::vector<at::Tensor> GR(kJ), Gt(kJ);
  GR[0] = R.select(1, 0);
  Gt[0] = J.select(1, 0);
  for (int d = 1; d <= max_depth; ++d) {
    std::vector<int64_t> idx, pidx;
    std::vector<at::Tensor> pGR, pGt;
    for (int j = 1; j < kJ; ++j) {
      if (depth[j] != d) continue;
      idx.push_back(j);
      pidx.push_back(m.parents[j]);
      pGR.push_back(GR[m.parents[j]]);
      pGt.push_back(Gt[m.parents[j]]);
    }
    const at::Tensor ji = at::tensor(idx, at::kLong), pi = at::tensor(pidx, at::kLong);
    const at::Tensor PR = at::stack(pGR, 1), Pt = at::stack(pGt, 1);  // [B, n, 3, 3], [B, n, 3]
    const at::Tensor rel = J.index_select(1, ji) - J.index_select(1, pi);
    const at::Tensor R_d = at::matmul(PR, R.index_select(1, ji));
    const at::Tensor t_d = at::matmul(PR, rel.unsqueeze(-1)).squeeze(-1) + Pt;
    const auto Rs = R_d.unbind(1), ts = t_d.unbind(1);
    for (size_t k = 0; k < idx.size(); ++k) {
      GR[idx[k]] = Rs[k];
      Gt[idx[k]] = ts[k];
    }
  }
  const at::Tensor GRs = at::stack(GR, 1);  // [B, 16, 3, 3]
  const at::Tensor Gts = at::stack(Gt, 1);  // [B, 16, 3]
  const at::Tensor At = Gts - at::matmul(GRs, J.unsqueeze(-1)).squeeze(-1);

  // Blend [R | t] per vertex in one product: [B·12, 16] x [16, V] -> [B, 12, V].
  const at::Tensor A = at::cat({GRs.reshape({B, kJ, 9}), At}, -1);  // [B, 16, 12]
  const at::Tensor T = at::mm(A.transpose(1, 2).reshape({B * 12, kJ}), m.weights_t).view({B, 12, V});
  // Rows 3r+c of T hold the blended R[r][c]: posed = t + Σ_c R[:, c] · v_c, over [B, 3, V].
  at::Tensor posed = T.slice(1, 9, 12) + trans.unsqueeze(-1);
  for (int c = 0; c < 3; ++c)
    posed = at::addcmul(posed, T.slice(1, c, 9, 3), v_posed.slice(1, c, c + 1));
  return {posed.transpose(1, 2).contiguous(), Gts + trans.unsqueeze(1)};
}

at::Tensor keypoints21(const HandModelTensors& m, const LbsTensors& posed) {
  return at::cat({posed.joints, posed.vertices.index_select(1, m.fingertips)}, 1);
}

}  // namespace bimart
