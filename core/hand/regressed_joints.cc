#include "core/hand/regressed_joints.h"

#include <map>

namespace bimart {

RegressedJoints RegressedJoints::from(const HandModel& m) {
  RegressedJoints r;
  std::map<int, int> index;  // model vertex → index into vertex_ids
  const auto add = [&](int v) {
    const auto [it, inserted] = index.emplace(v, static_cast<int>(r.vertex_ids.size()));
    if (inserted) r.vertex_ids.push_back(v);
    return it->second;
  };
  for (int j = 1; j < HandModel::kNumJoints; ++j)
    for (int v = 0; v < m.num_vertices(); ++v) {
      const double w = m.j_regressor(j, v);
      if (w != 0.0) r.rows[static_cast<size_t>(j)].emplace_back(add(v), w);
    }
  for (int f = 0; f < 5; ++f) r.tips[static_cast<size_t>(f)] = add(m.fingertips[static_cast<size_t>(f)]);
  r.sub = LbsSubset::from(m, r.vertex_ids);
  return r;
}

}  // namespace bimart
