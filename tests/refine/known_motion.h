// Test motions with a known answer: smooth random θ, β for both hands, posed by the
// shipped models, and their keypoints with Gaussian noise.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include <ATen/ATen.h>

#include "core/hand/finger_separation.h"
#include "core/hand/joint_limits.h"
#include "core/hand/keypoints.h"
#include "core/refine/hand_state.h"
#include "core/refine/mano_fit.h"

namespace bimart::test {

// N frames; hands 20 cm apart, turning and curling slowly; β ~ N(0, 1).
inline HandMotion known_motion(const std::array<const HandModel*, 2>& models, int N, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::array<std::vector<double>, 2> states, betas;
  for (int h = 0; h < 2; ++h) {
    std::vector<double> a(51), b(51), phase(51);
    for (int i = 0; i < 51; ++i) {
      // Fingers: the mean pose, a little noise, and each joint's curl swinging by ±40 %,
      // inside the anatomical limits (core/hand/joint_limits.h) as a real hand is.
      const double mean = i >= 3 && i < 48 ? models[h]->hands_mean[i - 3] : 0.0;
      a[i] = i < 3 ? 0.8 * g(rng) : (i < 48 ? mean + 0.04 * g(rng) : 0.05 * g(rng));
      b[i] = i < 3 ? 0.15 * g(rng) : (i < 48 ? 0.4 * mean : 0.02 * g(rng));
      phase[i] = 6.28 * std::uniform_real_distribution<double>(0, 1)(rng);
    }
    for (int i = 3; i < 48; ++i) phase[i] = phase[3 + 9 * ((i - 3) / 9)];  // a finger curls as one
    a[48] += h == 0 ? -0.1 : 0.1;
    states[h].resize(static_cast<size_t>(N) * 51);
    for (int t = 0; t < N; ++t)
      for (int i = 0; i < 51; ++i) states[h][t * 51 + i] = a[i] + b[i] * std::sin(0.15 * t + phase[i]);
    betas[h].resize(10);
    for (double& v : betas[h]) v = g(rng);
  }
  HandMotion m = hand_motion_from_states(states, betas, N);
  m.vertices = pose_hand_vertices(models, m);
  return m;
}

// [2, N, 100, 3] keypoints of `motion` plus N(0, sigma) per coordinate.
inline at::Tensor noisy_keypoints(const std::array<const HandModel*, 2>& models, const HandMotion& motion,
                                  double sigma_mm, unsigned seed) {
  std::vector<at::Tensor> per_hand;
  for (int h = 0; h < 2; ++h) {
    const std::vector<int> ids = model_keypoints(*models[h]);
    per_hand.push_back(motion.vertices[h].index_select(1, at::tensor(std::vector<int64_t>(ids.begin(), ids.end()))));
  }
  at::Tensor H = at::stack(per_hand).to(at::kDouble);
  if (sigma_mm > 0) {
    at::Generator gen = at::detail::createCPUGenerator(seed);
    H = H + at::normal(0.0, sigma_mm * 1e-3, H.sizes(), gen, at::TensorOptions().dtype(at::kDouble));
  }
  return H.to(at::kFloat);
}

// The largest angle (degrees) by which a joint of either hand in any frame of `motion`
// leaves its anatomical range (core/hand/joint_limits.h).
inline double largest_joint_excess(const std::array<const HandModel*, 2>& models, const HandMotion& motion) {
  double worst = 0;
  for (int h = 0; h < 2; ++h) {
    const JointLimits limits(*models[h]);
    const at::Tensor pose = motion.hands[h].pose.to(at::kDouble).contiguous();
    for (int64_t t = 0; t < pose.size(0); ++t)
      worst = std::max(worst, limits.largest_excess(Eigen::Map<const Eigen::VectorXd>(pose[t].data_ptr<double>(), 45)));
  }
  return worst;
}

// The closest two fingers' bones come over all frames and hands (m).
inline double closest_fingers(const std::array<const HandModel*, 2>& models, const HandMotion& m) {
  const at::Tensor V = pose_hands(models, m).vertices.to(at::kDouble).contiguous();
  double closest = 1;
  for (int h = 0; h < 2; ++h)
    for (int64_t t = 0; t < V.size(1); ++t) {
      const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> x(
          V[h][t].data_ptr<double>(), V.size(2), 3);
      const Eigen::Matrix<double, 16, 3> Jr = models[h]->j_regressor * x;  // as the measure reads them
      double joints[16][3], tips[5][3];
      for (int j = 0; j < 16; ++j)
        for (int k = 0; k < 3; ++k) joints[j][k] = Jr(j, k);
      for (int f = 0; f < 5; ++f)
        for (int k = 0; k < 3; ++k) tips[f][k] = x(models[h]->fingertips[f], k);
      closest = std::min(closest, bimart::closest_fingers(joints, tips));
    }
  return closest;
}

// Keypoints of `motion` whose index finger's middle and last phalanges (hand parts 2, 3)
// are moved `shift` (m) across the hand towards the middle finger, as a diffusion model's
// blurred fingers come; [2, N, 100, 3] float.
inline at::Tensor merged_keypoints(const std::array<const HandModel*, 2>& models, const HandMotion& motion, double shift) {
  at::Tensor H = noisy_keypoints(models, motion, 0.0, 0).to(at::kDouble).contiguous();
  const at::Tensor J = pose_hands(models, motion).joints.to(at::kDouble);
  for (int h = 0; h < 2; ++h) {
    const std::vector<int> ids = model_keypoints(*models[h]), part = hand_parts(*models[h]);
    for (int64_t t = 0; t < H.size(1); ++t) {
      const at::Tensor l = J[h][t][1] - J[h][t][7];
      const at::Tensor d = -shift * l / l.norm();
      for (std::size_t k = 0; k < ids.size(); ++k)
        if (part[static_cast<std::size_t>(ids[k])] == 2 || part[static_cast<std::size_t>(ids[k])] == 3)
          H[h][t][static_cast<int64_t>(k)] += d;
    }
  }
  return H.to(at::kFloat);
}

}  // namespace bimart::test
