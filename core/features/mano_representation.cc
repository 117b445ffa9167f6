#include "core/features/mano_representation.h"

#include <ATen/ATen.h>

#include <string>

#include "core/geometry/rotation.h"
#include "core/hand/lbs.h"
#include "core/hand/lbs_torch.h"
#include "core/object/object_batch.h"
#include "core/refine/mano_fit.h"
#include "core/util/error.h"

namespace bimart {
namespace {

constexpr int kJ = HandModel::kNumJoints;

std::string shape_of(const at::Tensor& t) { return t.defined() ? std::string(c10::str(t.sizes())) : "undefined"; }

// The root pose of every frame: rotation [N, 3, 3] and translation [N, 3], float64.
std::pair<at::Tensor, at::Tensor> root_pose(const at::Tensor& states, int64_t n) {
  if (!states.defined() || states.dim() != 2 || states.size(0) != n || states.size(1) != 7)
    throw Error("MANO representation: object_states must be [N, 7] with N = " + std::to_string(n) + ", got " +
                shape_of(states));
  const at::Tensor s = states.to(at::kCPU, at::kDouble);
  return {axis_angle_to_matrix_batch(s.narrow(1, 1, 3).contiguous()), s.narrow(1, 4, 3)};
}

// J0(β): the wrist's rest position, about which MANO applies the global rotation.
Eigen::Vector3d rest_wrist(const HandModel& model, const at::Tensor& shape) {
  if (!shape.defined() || shape.numel() != HandModel::kNumBetas)
    throw Error("MANO representation: shape must hold 10 values, got " + shape_of(shape));
  const at::Tensor b = shape.to(at::kCPU, at::kDouble).contiguous().view({-1});
  const Eigen::VectorXd betas = Eigen::Map<const Eigen::VectorXd>(b.data_ptr<double>(), HandModel::kNumBetas);
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  const Eigen::VectorXd pose = Eigen::VectorXd::Zero(HandModel::kPoseDim);
  return lbs<double>(model, zero, pose, zero, betas).joints.row(0).transpose();
}

}  // namespace

const std::vector<std::int64_t>& mano_representation_joint_columns() {
  static const std::vector<std::int64_t> columns = [] {
    std::vector<std::int64_t> c;
    for (int h = 0; h < 2; ++h)
      for (int i = 0; i < HandModel::kNumJoints * 3; ++i) c.push_back(h * kManoRepHandSize + kManoRepJoints + i);
    return c;
  }();
  return columns;
}

at::Tensor mano_representation_joints(const at::Tensor& rep) {
  if (rep.dim() < 1 || rep.size(-1) != kManoRepSize)
    throw Error("MANO-Rep joints: need [..., " + std::to_string(kManoRepSize) + "], got " + c10::str(rep.sizes()));
  const std::vector<std::int64_t>& c = mano_representation_joint_columns();
  return rep.index_select(-1, at::tensor(c, at::kLong));
}

at::Tensor rotation_to_6d(const at::Tensor& r) {
  return at::cat({r.select(-1, 0), r.select(-1, 1)}, -1);
}

at::Tensor rotation_from_6d(const at::Tensor& six) {
  if (!six.defined() || six.dim() < 1 || six.size(-1) != 6)
    throw Error("rotation_from_6d: need [..., 6], got " + shape_of(six));
  const at::Tensor a1 = six.narrow(-1, 0, 3), a2 = six.narrow(-1, 3, 3);
  const at::Tensor b1 = a1 / a1.norm(2, -1, true).clamp_min(1e-12);
  at::Tensor b2 = a2 - (b1 * a2).sum(-1, true) * b1;
  b2 = b2 / b2.norm(2, -1, true).clamp_min(1e-12);
  return at::stack({b1, b2, at::cross(b1, b2, -1)}, -1);  // the columns
}

at::Tensor mano_representation(const std::array<const HandModel*, 2>& models, const HandMotion& motion,
                               const at::Tensor& states) {
  at::NoGradGuard no_grad;
  const int64_t n = motion.num_frames();
  if (n < 1) throw Error("MANO representation: the hand motion has no frames");
  const auto [Rm, tm] = root_pose(states, n);
  HandMotion params = motion;
  params.vertices = at::Tensor();
  const at::Tensor joints = pose_hands(models, params).joints.to(at::kDouble);  // [2, N, 16, 3] world
  std::vector<at::Tensor> blocks;
  for (int h = 0; h < 2; ++h) {
    const HandParams& p = motion.hands[static_cast<std::size_t>(h)];
    const at::Tensor aa = at::cat({p.rot.to(at::kDouble).view({n, 1, 3}), p.pose.to(at::kDouble).view({n, kJ - 1, 3})}, 1);
    at::Tensor R = axis_angle_to_matrix(aa);  // [N, 16, 3, 3]; joint 0 in the world frame
    R = at::cat({at::matmul(Rm.transpose(1, 2), R.select(1, 0)).unsqueeze(1), R.slice(1, 1)}, 1);
    // Points: p_c = Rmᵀ (p − t), as rows (p − t)ᵀ Rm.
    const at::Tensor jc = at::matmul(joints[h] - tm.unsqueeze(1), Rm);  // [N, 16, 3]
    blocks.push_back(rotation_to_6d(R).reshape({n, kJ * 6}));
    blocks.push_back(jc.select(1, 0));
    blocks.push_back(jc.reshape({n, kJ * 3}));
  }
  return at::cat(blocks, 1).to(at::kFloat).contiguous();
}

HandMotion hands_from_mano_representation(const std::array<const HandModel*, 2>& models, const at::Tensor& rep,
                                          const at::Tensor& states, const std::array<at::Tensor, 2>& shapes) {
  at::NoGradGuard no_grad;
  if (!rep.defined() || rep.dim() != 2 || rep.size(1) != kManoRepSize)
    throw Error("MANO representation: need [N, " + std::to_string(kManoRepSize) + "], got " + shape_of(rep));
  const int64_t n = rep.size(0);
  const auto [Rm, tm] = root_pose(states, n);
  const at::Tensor x = rep.to(at::kCPU, at::kDouble);
  if (!at::isfinite(x).all().item<bool>()) throw Error("MANO representation: the sample holds values that are not finite");
  HandMotion out;
  for (int h = 0; h < 2; ++h) {
    const at::Tensor block = x.narrow(1, h * kManoRepHandSize, kManoRepHandSize);
    at::Tensor R = rotation_from_6d(block.narrow(1, 0, kJ * 6).reshape({n, kJ, 6}));  // [N, 16, 3, 3]
    R = at::cat({at::matmul(Rm, R.select(1, 0)).unsqueeze(1), R.slice(1, 1)}, 1).contiguous();
    const at::Tensor wrist = at::matmul(Rm, block.narrow(1, kManoRepWrist, 3).unsqueeze(-1)).squeeze(-1) + tm;
    const Eigen::Vector3d j0 = rest_wrist(*models[static_cast<std::size_t>(h)], shapes[static_cast<std::size_t>(h)]);
    at::Tensor aa = at::empty({n, kJ, 3}, at::kDouble);
    const double* Rp = R.data_ptr<double>();
    double* A = aa.data_ptr<double>();
    for (int64_t k = 0; k < n * kJ; ++k) {
      const Eigen::Matrix3d m = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(Rp + 9 * k);
      Eigen::Map<Eigen::Vector3d>(A + 3 * k) = matrix_to_axis_angle(m);
    }
    HandParams& p = out.hands[static_cast<std::size_t>(h)];
    p.rot = aa.select(1, 0).to(at::kFloat).contiguous();
    p.pose = aa.slice(1, 1).reshape({n, HandModel::kPoseDim}).to(at::kFloat).contiguous();
    p.trans = (wrist - at::tensor({j0.x(), j0.y(), j0.z()}, at::kDouble)).to(at::kFloat).contiguous();
    p.shape = shapes[static_cast<std::size_t>(h)].to(at::kCPU, at::kFloat).reshape({HandModel::kNumBetas}).contiguous();
  }
  return out;
}

}  // namespace bimart
