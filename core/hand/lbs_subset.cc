#include "core/hand/lbs_subset.h"

#include <string>

#include "core/util/error.h"

namespace bimart {

LbsSubset LbsSubset::from(const HandModel& model, const std::vector<int>& vertex_ids) {
  constexpr int kJ = HandModel::kNumJoints;
  const int V = model.num_vertices();
  LbsSubset m;
  m.vertex_ids = vertex_ids;
  m.parents = model.parents;
  const int S = m.size();
  m.v_template.resize(S, 3);
  m.shapedirs.resize(3 * S, HandModel::kNumBetas);
  m.posedirs.resize(3 * S, HandModel::kNumPoseFeatures);
  m.weight_start.assign(1, 0);
  for (int s = 0; s < S; ++s) {
    const int i = vertex_ids[static_cast<size_t>(s)];
    if (i < 0 || i >= V)
      throw Error("LbsSubset: vertex " + std::to_string(i) + " is out of range (the hand has " +
                  std::to_string(V) + ")");
    m.v_template.row(s) = model.v_template.row(i);
    for (int k = 0; k < 3; ++k) {
      m.shapedirs.row(3 * s + k) = model.shapedirs.row(3 * i + k);
      m.posedirs.row(3 * s + k) = model.posedirs.row(3 * i + k);
    }
    for (int j = 0; j < kJ; ++j) {
      const double w = model.weights(i, j);
      if (w == 0.0) continue;
      m.weight_joint.push_back(j);
      m.weight_value.push_back(w);
    }
    m.weight_start.push_back(static_cast<int>(m.weight_joint.size()));
  }
  m.has_pose_correctives = m.posedirs.size() > 0 && m.posedirs.cwiseAbs().maxCoeff() > 0;
  // J = J_regressor · (v_template + shapedirs·β): both parts once, for every vertex.
  for (int j = 0; j < kJ; ++j) {
    m.j_template.row(j) = model.j_regressor.row(j) * model.v_template;
    for (int k = 0; k < 3; ++k) {
      Eigen::Matrix<double, 1, HandModel::kNumBetas> row = Eigen::Matrix<double, 1, HandModel::kNumBetas>::Zero();
      for (int i = 0; i < V; ++i) {
        const double w = model.j_regressor(j, i);
        if (w != 0.0) row += w * model.shapedirs.row(3 * i + k);
      }
      m.j_shapedirs.row(3 * j + k) = row;
    }
  }
  return m;
}

}  // namespace bimart
