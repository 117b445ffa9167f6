#include "core/refine/hand_state.h"

#include <string>

#include <ATen/ATen.h>

#include "core/hand/hand_model.h"
#include "core/util/error.h"

namespace bimart {

HandMotion hand_motion_from_states(const std::array<std::vector<double>, 2>& states,
                                   const std::array<std::vector<double>, 2>& betas, int64_t N) {
  HandMotion motion;
  for (size_t h = 0; h < 2; ++h) {
    const at::Tensor x = at::from_blob(const_cast<double*>(states[h].data()), {N, kHandStateSize}, at::kDouble)
                             .to(at::kFloat);
    HandParams& p = motion.hands[h];
    p.rot = x.slice(1, 0, 3).contiguous();
    p.pose = x.slice(1, 3, 48).contiguous();
    p.trans = x.slice(1, 48, 51).contiguous();
    p.shape = at::from_blob(const_cast<double*>(betas[h].data()), {HandModel::kNumBetas}, at::kDouble).to(at::kFloat);
  }
  return motion;
}

void states_from_hand_motion(const HandMotion& motion, int hand, std::vector<double>* states,
                             std::vector<double>* beta) {
  const HandParams& p = motion.hands[static_cast<size_t>(hand)];
  const int64_t N = motion.num_frames();
  auto check = [&](const at::Tensor& t, int64_t cols, const char* name) {
    if (!t.defined() || t.dim() != 2 || t.size(0) != N || t.size(1) != cols)
      throw Error(std::string("hand ") + std::to_string(hand) + " " + name + " must be [" +
                  std::to_string(N) + ", " + std::to_string(cols) + "]");
  };
  check(p.rot, 3, "rot");
  check(p.pose, HandModel::kPoseDim, "pose");
  check(p.trans, 3, "trans");
  if (!p.shape.defined() || p.shape.numel() != HandModel::kNumBetas)
    throw Error("hand " + std::to_string(hand) + " shape must hold 10 values");
  const at::Tensor x = at::cat({p.rot, p.pose, p.trans}, 1).to(at::kDouble).contiguous();
  states->assign(x.data_ptr<double>(), x.data_ptr<double>() + N * kHandStateSize);
  const at::Tensor b = p.shape.to(at::kDouble).contiguous().reshape({-1});
  beta->assign(b.data_ptr<double>(), b.data_ptr<double>() + HandModel::kNumBetas);
}

}  // namespace bimart
