#include "core/refine/mano_fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include <ATen/ATen.h>
#include <Eigen/Geometry>

#include "core/geometry/rotation.h"
#include "core/geometry/point_guard.h"
#include "core/hand/joint_limits.h"
#include "core/hand/keypoints.h"
#include "core/hand/lbs_subset.h"
#include "core/hand/lbs_torch.h"
#include "core/hand/regressed_joints.h"
#include "core/refine/hand_state.h"
#include "core/util/error.h"
#include "core/util/parallel.h"

namespace bimart {
namespace {

constexpr int kJ = 100;  // keypoints per hand (DESIGN §4)
constexpr int kX = kHandStateSize;
constexpr int kB = HandModel::kNumBetas;
constexpr double kLeverRot = 0.1, kLeverFinger = 0.03, kLeverShape = 0.01;

// Keypoints of one frame: K(θ, β) − Ĥ, 300 lengths.
struct KeypointCost {
  const LbsSubset* sub;
  const double* target;  // [300]
  template <class T>
  bool operator()(const T* x, const T* beta, T* r) const {
    lbs_subset(*sub, x, x + 3, x + 48, beta, r);
    for (int i = 0; i < 3 * kJ; ++i) r[i] -= target[i];
    return true;
  }
};

// ℓ ⊙ (θ_t − θ_{t−1}) · √weight.
struct SmoothCost {
  double scale;  // √(w_smooth · J)
  template <class T>
  bool operator()(const T* a, const T* b, T* r) const {
    for (int i = 0; i < kX; ++i) {
      const double lever = i < 3 ? kLeverRot : (i < 48 ? kLeverFinger : 1.0);
      r[i] = scale * lever * (b[i] - a[i]);
    }
    return true;
  }
};

struct PosePriorCost {
  double scale;  // √(w_pose · J) · ℓ_f
  const double* mean;
  template <class T>
  bool operator()(const T* x, T* r) const {
    for (int i = 0; i < HandModel::kPoseDim; ++i) r[i] = scale * (x[3 + i] - mean[i]);
    return true;
  }
};

// Anatomical joint limits: ℓ_f · (angle beyond its range) · √(w_limits · J), 45 per frame.
struct JointLimitCost {
  const JointLimits* limits;
  double scale;
  template <class T>
  bool operator()(const T* x, T* r) const {
    limits->scaled_excess(0, 15, x + 3, scale, r);
    return true;
  }
};

// Fingers side by side (core/hand/finger_order.h): scale · max(0, shortfall), 8 per frame.
struct FingerOrderCost {
  const LbsSubset* tips;  // the five fingertip vertices
  double gap, scale;
  template <class T>
  bool operator()(const T* x, const T* beta, T* r) const {
    T tip[5][3], J[HandModel::kNumJoints][3];
    lbs_subset(*tips, x, x + 3, x + 48, beta, &tip[0][0], &J[0][0]);
    finger_order_shortfall<T>(J, tip, gap, r);
    for (int i = 0; i < kFingerOrderResiduals; ++i) r[i] = r[i] > T(0) ? T(scale) * r[i] : T(0);
    return true;
  }
};

ceres::CostFunction* finger_order_cost(const LbsSubset& tips, const ManoFitOptions& opt) {
  return new ceres::AutoDiffCostFunction<FingerOrderCost, kFingerOrderResiduals, kX, kB>(
      new FingerOrderCost{&tips, opt.finger_gap, std::sqrt(opt.w_fingers * kJ)});
}

// Fingers apart (core/hand/finger_separation.h): scale · max(0, gap − distance), 90 per
// frame, between bones through the joints the measure regresses from the vertices.
struct FingerSeparationCost {
  const RegressedJoints* rj;
  double gap, scale;
  template <class T>
  bool operator()(const T* x, const T* beta, T* r) const {
    T tip[5][3], J[HandModel::kNumJoints][3];
    rj->pose(x, beta, J, tip);
    finger_separation_shortfall<T>(J, tip, gap, r);
    for (int i = 0; i < kFingerSeparationResiduals; ++i) r[i] *= T(scale);
    return true;
  }
};

// The closest two fingers' bones come in frame state x (m).
double closest_fingers(const RegressedJoints& rj, const double* x, const double* beta) {
  double tip[5][3], J[HandModel::kNumJoints][3];
  rj.pose(x, beta, J, tip);
  return bimart::closest_fingers(J, tip);
}

ceres::CostFunction* finger_separation_cost(const RegressedJoints& rj, const ManoFitOptions& opt) {
  return new ceres::AutoDiffCostFunction<FingerSeparationCost, kFingerSeparationResiduals, kX, kB>(
      new FingerSeparationCost{&rj, opt.separation_gap, std::sqrt(opt.w_separation * kJ)});
}

ceres::CostFunction* joint_limit_cost(const JointLimits& limits, double w_limits) {
  return new ceres::AutoDiffCostFunction<JointLimitCost, HandModel::kPoseDim, kX>(
      new JointLimitCost{&limits, std::sqrt(w_limits * kJ) * kLeverFinger});
}

struct ShapePriorCost {
  double scale;  // √(w_shape · J · N) · ℓ_β
  template <class T>
  bool operator()(const T* beta, T* r) const {
    for (int i = 0; i < kB; ++i) r[i] = scale * beta[i];
    return true;
  }
};

ceres::CostFunction* keypoint_cost(const LbsSubset& sub, const double* target) {
  return new ceres::AutoDiffCostFunction<KeypointCost, 3 * kJ, kX, kB>(new KeypointCost{&sub, target});
}

// Rigid motion (R, t) that best maps `from` onto `to` (rows are points), Umeyama.
Eigen::Isometry3d align(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) {
  Eigen::Isometry3d T;
  T.matrix() = Eigen::umeyama(from, to, false);
  return T;
}

// Moves hand state x rigidly by T in the world: posing(x') = T · posing(x). MANO rotates
// about the root joint J0, so trans' = R·(J0 + trans) + t − J0.
void move_rigidly(double* x, const Eigen::Isometry3d& T, const Eigen::Vector3d& j0) {
  const Eigen::Matrix3d R = T.linear() * axis_angle_to_matrix(Eigen::Vector3d(x[0], x[1], x[2]));
  const Eigen::Vector3d aa = matrix_to_axis_angle(R);
  const Eigen::Vector3d tr = T.linear() * (j0 + Eigen::Vector3d(x[48], x[49], x[50])) + T.translation() - j0;
  for (int k = 0; k < 3; ++k) {
    x[k] = aa[k];
    x[48 + k] = tr[k];
  }
}

void solve(ceres::Problem* problem, int max_iterations, ceres::LinearSolverType solver,
           ceres::Solver::Summary* summary) {
  ceres::Solver::Options o;
  o.linear_solver_type = solver;
  o.max_num_iterations = max_iterations;
  o.num_threads = 1;  // one hand per thread
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  o.function_tolerance = 1e-9;
  o.parameter_tolerance = 1e-10;
  ceres::Solve(o, problem, summary);
}

ceres::LinearSolverType sparse_solver() {
  return ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ||
                 ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE)
             ? ceres::SPARSE_NORMAL_CHOLESKY
             : ceres::DENSE_NORMAL_CHOLESKY;
}

// One hand: targets [N, 300] row-major. Returns states [N, 51] and β.
void fit_hand(const HandModel& model, const std::vector<double>& targets, int64_t N,
              const ManoFitOptions& opt, std::vector<double>* states, std::vector<double>* beta,
              ManoFitHandReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<int> ids = model_keypoints(model);
  const LbsSubset sub = LbsSubset::from(model, ids);
  const std::vector<int> parts = hand_parts(model);
  std::vector<int> palm;  // keypoints on the palm (the wrist part): rigid alignment
  for (int k = 0; k < kJ; ++k)
    if (parts[static_cast<size_t>(ids[static_cast<size_t>(k)])] == 0) palm.push_back(k);
  if (palm.size() < 3)
    for (int k = 0; k < kJ; ++k) palm.push_back(k);  // a model without palm keypoints

  states->assign(static_cast<size_t>(N * kX), 0.0);
  beta->assign(kB, 0.0);
  const double* mean = model.hands_mean.data();
  const double prior_scale = std::sqrt(opt.w_pose * kJ) * kLeverFinger;
  const JointLimits limits(model);
  const LbsSubset tips = LbsSubset::from(model, std::vector<int>(model.fingertips.begin(), model.fingertips.end()));
  const RegressedJoints rj = RegressedJoints::from(model);
  // A frame whose fingers come near the gap carries the separation term (kSeparationActive).
  const auto near_gap = [&](const double* x) {
    return opt.w_separation > 0 && closest_fingers(rj, x, beta->data()) < opt.separation_gap + kSeparationActive;
  };

  auto palm_points = [&](const double* v300) {
    Eigen::Matrix3Xd p(3, static_cast<Eigen::Index>(palm.size()));
    for (size_t i = 0; i < palm.size(); ++i)
      for (int k = 0; k < 3; ++k) p(k, static_cast<Eigen::Index>(i)) = v300[3 * palm[i] + k];
    return p;
  };
  const Eigen::Vector3d j0(sub.j_template(0, 0), sub.j_template(0, 1), sub.j_template(0, 2));
  std::vector<double> posed(3 * kJ);

  // Sequential warm start, β = 0.
  for (int64_t t = 0; t < N; ++t) {
    double* x = states->data() + t * kX;
    if (t == 0) {
      for (int i = 0; i < HandModel::kPoseDim; ++i) x[3 + i] = mean[i];
    } else {
      std::copy(x - kX, x, x);
    }
    lbs_subset(sub, x, x + 3, x + 48, beta->data(), posed.data());
    move_rigidly(x, align(palm_points(posed.data()), palm_points(targets.data() + t * 3 * kJ)), j0);
    if (opt.warm_start_iterations > 0) {
      ceres::Problem p;
      p.AddResidualBlock(keypoint_cost(sub, targets.data() + t * 3 * kJ), nullptr, x, beta->data());
      p.AddResidualBlock(new ceres::AutoDiffCostFunction<PosePriorCost, HandModel::kPoseDim, kX>(
                             new PosePriorCost{prior_scale, mean}),
                         nullptr, x);
      if (opt.w_limits > 0) p.AddResidualBlock(joint_limit_cost(limits, opt.w_limits), nullptr, x);
      if (opt.w_fingers > 0) p.AddResidualBlock(finger_order_cost(tips, opt), nullptr, x, beta->data());
      p.SetParameterBlockConstant(beta->data());
      ceres::Solver::Summary s;
      solve(&p, opt.warm_start_iterations, ceres::DENSE_NORMAL_CHOLESKY, &s);
      if (near_gap(x)) {  // again, with the fingers held apart
        p.AddResidualBlock(finger_separation_cost(rj, opt), nullptr, x, beta->data());
        solve(&p, opt.warm_start_iterations, ceres::DENSE_NORMAL_CHOLESKY, &s);
      }
    }
  }

  // Joint solve over all frames and β.
  ceres::Problem problem;
  for (int64_t t = 0; t < N; ++t) {
    double* x = states->data() + t * kX;
    problem.AddResidualBlock(keypoint_cost(sub, targets.data() + t * 3 * kJ), nullptr, x, beta->data());
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PosePriorCost, HandModel::kPoseDim, kX>(
                                 new PosePriorCost{prior_scale, mean}),
                             nullptr, x);
    if (opt.w_limits > 0) problem.AddResidualBlock(joint_limit_cost(limits, opt.w_limits), nullptr, x);
    if (opt.w_fingers > 0) problem.AddResidualBlock(finger_order_cost(tips, opt), nullptr, x, beta->data());
    if (t > 0)
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<SmoothCost, kX, kX, kX>(
                                   new SmoothCost{std::sqrt(opt.w_smooth * kJ)}),
                               nullptr, x - kX, x);
  }
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ShapePriorCost, kB, kB>(new ShapePriorCost{
                               std::sqrt(opt.w_shape * kJ * static_cast<double>(N)) * kLeverShape}),
                           nullptr, beta->data());
  if (!opt.fit_shape) problem.SetParameterBlockConstant(beta->data());
  ceres::Solver::Summary summary;
  int separation_steps = 0;  // of the first solve, when a second one holds fingers apart
  solve(&problem, opt.max_iterations, sparse_solver(), &summary);
  // Fingers apart: the joint solve can close up fingers the warm start kept apart, so the
  // frames near the gap after it get the term and the solve goes on from there.
  bool separated = false;
  for (int64_t t = 0; t < N; ++t) {
    double* x = states->data() + t * kX;
    if (!near_gap(x)) continue;
    problem.AddResidualBlock(finger_separation_cost(rj, opt), nullptr, x, beta->data());
    separated = true;
  }
  if (separated) {
    const double initial = summary.initial_cost;
    const int steps = static_cast<int>(summary.iterations.size()) - 1;
    solve(&problem, opt.max_iterations, sparse_solver(), &summary);
    summary.initial_cost = initial;
    separation_steps = steps;
  }
  // What the penalty leaves outside a range goes onto its edge (core/hand/joint_limits.h).
  if (opt.w_limits > 0)
    for (int64_t t = 0; t < N; ++t) limits.clamp_pose(states->data() + t * kX + 3);

  double err = 0;
  for (int64_t t = 0; t < N; ++t) {
    const double* x = states->data() + t * kX;
    lbs_subset(sub, x, x + 3, x + 48, beta->data(), posed.data());
    for (int k = 0; k < kJ; ++k) {
      const double* q = targets.data() + t * 3 * kJ + 3 * k;
      err += std::sqrt((posed[3 * k] - q[0]) * (posed[3 * k] - q[0]) +
                       (posed[3 * k + 1] - q[1]) * (posed[3 * k + 1] - q[1]) +
                       (posed[3 * k + 2] - q[2]) * (posed[3 * k + 2] - q[2]));
    }
  }
  report->initial_cost = summary.initial_cost;
  report->final_cost = summary.final_cost;
  report->iterations = separation_steps + static_cast<int>(summary.iterations.size()) - 1;
  report->mean_keypoint_error = err / static_cast<double>(N * kJ);
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

void ManoFitOptions::validate() const {
  auto nonneg = [](double v, const char* name) {
    if (!(v >= 0) || !std::isfinite(v))
      throw Error(std::string("mano fit: ") + name + " must be a finite number >= 0");
  };
  nonneg(w_pose, "w_pose");
  nonneg(w_shape, "w_shape");
  nonneg(w_smooth, "w_smooth");
  nonneg(w_limits, "w_limits");
  nonneg(w_fingers, "w_fingers");
  nonneg(finger_gap, "finger_gap");
  nonneg(w_separation, "w_separation");
  nonneg(separation_gap, "separation_gap");
  if (warm_start_iterations < 0) throw Error("mano fit: warm_start_iterations must be >= 0");
  if (max_iterations < 0) throw Error("mano fit: max_iterations must be >= 0");
  if (threads < 0) throw Error("mano fit: threads must be >= 0 (0 = all cores)");
}


HandMotion fit_mano(const std::array<const HandModel*, 2>& models, const at::Tensor& keypoints_world,
                    const ManoFitOptions& options, ManoFitReport* report) {
  options.validate();
  const at::Tensor& H = keypoints_world;
  if (H.dim() != 4 || H.size(0) != 2 || H.size(2) != kJ || H.size(3) != 3 || H.size(1) < 1)
    throw Error("mano fit: keypoints must be [2, N, 100, 3] with N >= 1, got " + std::string(c10::str(H.sizes())));
  const at::Tensor Hd = H.to(at::kCPU, at::kDouble).contiguous();
  if (first_out_of_bounds(Hd.data_ptr<double>(), static_cast<long>(Hd.numel()), kMaxCoordinate) >= 0)
    throw Error("mano fit: keypoints hold values that are not finite or beyond 10 km (diverged input?)");
  const int64_t N = H.size(1);
  const auto t0 = std::chrono::steady_clock::now();

  std::array<std::vector<double>, 2> states, betas;
  ManoFitReport local;
  parallel_for(2, resolve_threads(options.threads), [&](std::size_t h) {
    const double* p = Hd[static_cast<int64_t>(h)].data_ptr<double>();
    const std::vector<double> targets(p, p + N * 3 * kJ);
    fit_hand(*models[h], targets, N, options, &states[h], &betas[h], &local.hands[h]);
  });

  HandMotion motion = hand_motion_from_states(states, betas, N);
  motion.vertices = pose_hand_vertices(models, motion);
  local.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (report) *report = local;
  return motion;
}

PosedHands pose_hands(const std::array<const HandModel*, 2>& models, const HandMotion& motion) {
  at::NoGradGuard no_grad;
  const int64_t N = motion.num_frames();
  std::vector<at::Tensor> vertices, joints;
  for (int h = 0; h < 2; ++h) {
    const HandModelTensors m = HandModelTensors::from(*models[static_cast<size_t>(h)], at::kDouble);
    const HandParams& p = motion.hands[static_cast<size_t>(h)];
    auto d = [](const at::Tensor& t) { return t.to(at::kDouble).contiguous(); };
    const LbsTensors r =
        lbs(m, d(p.rot), d(p.pose), d(p.trans), d(p.shape).reshape({1, -1}).expand({N, -1}).contiguous());
    vertices.push_back(r.vertices.to(at::kFloat));
    joints.push_back(r.joints.to(at::kFloat));
  }
  return {at::stack(vertices), at::stack(joints)};
}

}  // namespace bimart
