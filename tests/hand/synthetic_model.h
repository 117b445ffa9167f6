// A small random hand model in MANO layout for tests and benchmarks: MANO's kinematic tree,
// V vertices, sparse joint regressor and skinning weights like the real files.
#pragma once

#include <algorithm>
#include <random>

#include <Eigen/QR>

#include "core/hand/hand_model.h"

namespace bimart::testing {

inline HandModel make_synthetic_hand(int V = 50, unsigned seed = 7, HandSide side = HandSide::Right) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> vid(0, V - 1);
  auto rand = [&](Eigen::Index r, Eigen::Index c, double scale) {
    Eigen::MatrixXd m(r, c);
    for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = scale * u(rng);
    return m;
  };
  HandModel m;
  m.side = side;
  m.parents = {-1, 0, 1, 2, 0, 4, 5, 0, 7, 8, 0, 10, 11, 0, 13, 14};
  m.v_template = rand(V, 3, 0.08);
  m.shapedirs = rand(3 * V, 10, 0.01);
  m.posedirs = rand(3 * V, 135, 0.005);
  // Each joint: the mean of 4 random vertices.
  m.j_regressor = Eigen::MatrixXd::Zero(16, V);
  for (int j = 0; j < 16; ++j)
    for (int k = 0; k < 4; ++k) m.j_regressor(j, vid(rng)) += 0.25;
  // Each vertex: 1 to 3 joints with positive weights summing to 1.
  m.weights = Eigen::MatrixXd::Zero(V, 16);
  std::uniform_int_distribution<int> jid(0, 15), count(1, 3);
  for (int v = 0; v < V; ++v) {
    const int n = count(rng);
    for (int k = 0; k < n; ++k) m.weights(v, jid(rng)) += 0.2 + 0.5 * (u(rng) + 1.0);
    m.weights.row(v) /= m.weights.row(v).sum();
  }
  const int F = 2 * V;
  m.faces.resize(F, 3);
  for (int f = 0; f < F; ++f) m.faces.row(f) << vid(rng), vid(rng), vid(rng);
  // An orthonormal PCA basis, as MANO's.
  m.hands_components = Eigen::HouseholderQR<Eigen::MatrixXd>(rand(45, 45, 1.0)).householderQ();
  m.hands_mean = rand(45, 1, 0.3);
  for (int i = 0; i < 5; ++i) m.fingertips[i] = (7 * i + 3) % V;
  for (int i = 0; i < 10; ++i) m.keypoints.push_back((5 * i + 1) % V);
  return m;
}

}  // namespace bimart::testing
