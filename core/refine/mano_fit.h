// Fitting MANO-layout hands to predicted surface keypoints (paper §3.4 eq. 8, DESIGN §5):
// per hand, θ per frame (rot, pose, trans: 51) and one β per sequence, by Ceres with
// automatic derivatives through lbs_subset (core/hand/lbs_subset.h).
//
// Cost per hand, in metres² (each residual is a length):
//   Σ_t Σ_k ||K_k(θ_t, β) − Ĥ_tk||²                          keypoints
//   + w_pose   · J · Σ_t ||ℓ_f (pose_t − mean pose)||²        weak pose prior
//   + w_shape  · J · N · ||ℓ_β β||²                           weak shape prior
//   + w_smooth · J · Σ_t ||ℓ ⊙ (θ_t − θ_{t−1})||²             temporal smoothness
//   + w_limits · J · Σ_t ||ℓ_f · excess(pose_t)||²            anatomical joint limits (ours)
// with lever arms ℓ turning angles into lengths (ℓ_rot = 0.1 m for the wrist, ℓ_f = 0.03 m
// for the fingers, 1 for translation, ℓ_β = 0.01 m per unit of β), and J = 100 keypoints,
// so a weight of 1 makes a term count like the keypoints do. excess() is each finger joint's
// flexion, abduction and twist beyond its anatomical range (core/hand/joint_limits.h): 0
// inside, so the limits change nothing a plausible hand does; after the solve every joint
// still outside its range is clamped onto it (JointLimits::clamp).
//
// Solve: frame 0 from a rigid alignment of the palm keypoints (Umeyama) at the mean pose;
// every next frame warm-started from its neighbour's solution (moved rigidly onto the
// frame's palm keypoints) and solved alone for a few steps; then all frames and β jointly.
// Frames couple only through β and the smoothness term, a banded system that the sparse
// normal-equation Cholesky solves in linear time. The two hands are independent problems
// and run on two threads.
#pragma once

#include <array>
#include <string>

#include <ATen/core/Tensor.h>

#include "core/hand/hand_model.h"
#include "core/hand/keypoints.h"  // model_keypoints
#include "core/hand/finger_order.h"
#include "core/hand/finger_separation.h"
#include "core/hand/hand_motion.h"

namespace bimart {

struct ManoFitOptions {
  double w_pose = 1e-3;    // pose prior towards MANO's mean finger pose
  double w_shape = 1e-3;   // shape prior towards β = 0
  double w_smooth = 1e-2;  // first differences of θ between frames
  // Joint limits: a joint 1° beyond its range costs as much as all 100 keypoints 5 mm off.
  double w_limits = 100;
  // Fingers side by side (core/hand/finger_order.h): a PIP, DIP or tip 1 mm short of its
  // gap to the neighbouring finger costs as much as all 100 keypoints √w_fingers mm off.
  // 0 = off.
  double w_fingers = 0;
  double finger_gap = kFingerGap;  // m
  // Fingers apart (core/hand/finger_separation.h): two fingers' bones 1 mm inside the gap
  // cost as much as all 100 keypoints √w_separation mm off (100: 10 mm). 0 = off. On
  // generated samples Implaus after the fit 5.0 → 0.0 % (docs/refinement.md).
  double w_separation = 100;
  double separation_gap = kFingerSeparation;  // m
  bool fit_shape = true;   // false: β stays 0
  int warm_start_iterations = 3;  // per frame, sequentially
  int max_iterations = 30;        // the joint solve
  int threads = 0;                // 0: all cores (the hands run in parallel)
  void validate() const;          // throws bimart::Error naming the option
};

struct ManoFitHandReport {
  double initial_cost = 0, final_cost = 0;  // Ceres' ½Σr² of the joint solve
  int iterations = 0;                       // of the joint solve
  double mean_keypoint_error = 0;           // m, mean over frames and keypoints
  double seconds = 0;
};
struct ManoFitReport {
  std::array<ManoFitHandReport, 2> hands;
  double seconds = 0;  // wall time of the whole fit
};

// Fits both hands to keypoints [2, N, J, 3] (world frame, J = 100 in each model's keypoint
// order). models: {left, right}. Returns the motion with posed vertices [2, N, V, 3].
// Throws bimart::Error for shapes that do not match or values that are not finite.
HandMotion fit_mano(const std::array<const HandModel*, 2>& models, const at::Tensor& keypoints_world,
                    const ManoFitOptions& options = {}, ManoFitReport* report = nullptr);

// Posed vertices [2, N, V, 3] and joints [2, N, 16, 3] (float32, world frame) of a
// motion's parameters (full LBS, core/hand/lbs_torch.h).
struct PosedHands {
  at::Tensor vertices, joints;
};
PosedHands pose_hands(const std::array<const HandModel*, 2>& models, const HandMotion& motion);
inline at::Tensor pose_hand_vertices(const std::array<const HandModel*, 2>& models, const HandMotion& motion) {
  return pose_hands(models, motion).vertices;
}


}  // namespace bimart
