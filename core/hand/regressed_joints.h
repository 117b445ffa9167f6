// The finger joints and fingertips as the hand-plausibility measure reads them
// (core/metrics/hand_plausibility.h): joints regressed from the posed vertices by the
// model's joint regressor, not the kinematic chain's joints — on a bent finger the two
// differ by millimetres (the skinned ring of vertices around a joint does not stay centred
// on it), enough for a term on the chain's joints to hold fingers apart that the measure
// still calls crossed. A cost poses only the vertices the regressor reads
// (core/hand/lbs_subset.h), then combines them here.
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "core/hand/hand_model.h"
#include "core/hand/lbs_subset.h"

namespace bimart {

struct RegressedJoints {
  std::vector<int> vertex_ids;  // the vertices to pose: the regressor's support for joints 1-15, then the 5 fingertips
  std::array<std::vector<std::pair<int, double>>, HandModel::kNumJoints> rows;  // per joint: (index into vertex_ids, weight); joint 0 empty
  std::array<int, 5> tips{};  // index into vertex_ids of each fingertip (thumb, index, middle, ring, pinky)
  LbsSubset sub;              // vertex_ids, to pose
  static RegressedJoints from(const HandModel& model);

  // The joints and tips of frame state x (rot 3, pose 45, trans 3) with shape beta: the
  // vertices posed (lbs_subset), then apply(); any scalar types (Ceres Jets).
  template <class T, class TB>
  void pose(const T* x, const TB* beta, T (*joints)[3], T (*tip)[3]) const {
    std::vector<T> posed(static_cast<size_t>(3 * sub.size()));
    lbs_subset(sub, x, x + 3, x + 48, beta, posed.data());
    apply(posed.data(), joints, tip);
  }

  // posed [3 × vertex_ids.size()] (x, y, z per vertex) → joints [16][3] (row 0, the wrist,
  // left zero) and tips [5][3]; any scalar type (Ceres Jets).
  template <class T>
  void apply(const T* posed, T (*joints)[3], T (*tip)[3]) const {
    for (int k = 0; k < 3; ++k) joints[0][k] = T(0);
    for (int j = 1; j < HandModel::kNumJoints; ++j) {
      for (int k = 0; k < 3; ++k) joints[j][k] = T(0);
      for (const auto& [i, w] : rows[static_cast<size_t>(j)])
        for (int k = 0; k < 3; ++k) joints[j][k] += w * posed[3 * i + k];
    }
    for (int f = 0; f < 5; ++f)
      for (int k = 0; k < 3; ++k) tip[f][k] = posed[3 * tips[static_cast<size_t>(f)] + k];
  }
};

}  // namespace bimart
