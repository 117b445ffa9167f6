#include "manipulation_stages.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/util/error.h"

namespace bimart {
namespace {

constexpr double kAngleStep = 1e-3;   // rad per frame: the hinge turns (as the Art metric)
constexpr double kMoveStep = 1e-4;    // m or rad per frame: the object moves

}  // namespace

std::vector<ManipulationStage> manipulation_stages(const at::Tensor& states_in, std::int64_t min_frames) {
  const at::Tensor s = states_in.to(at::kDouble).contiguous();
  if (s.dim() != 2 || s.size(1) != 7 || s.size(0) < 1) throw Error("manipulation stages: object_states must be [N >= 1, 7]");
  const std::int64_t N = s.size(0);
  const double* p = s.data_ptr<double>();
  std::vector<int> what(static_cast<std::size_t>(N), 0);
  for (std::int64_t t = 0; t + 1 < N; ++t) {
    const double* a = p + 7 * t;
    const double* b = a + 7;
    double move = 0;
    for (int k = 1; k < 7; ++k) move = std::max(move, std::abs(b[k] - a[k]));
    what[static_cast<std::size_t>(t)] = std::abs(b[0] - a[0]) > kAngleStep ? 2 : move > kMoveStep ? 1 : 0;
  }
  if (N > 1) what.back() = what[static_cast<std::size_t>(N - 2)];
  std::vector<ManipulationStage> stages;
  for (std::int64_t t = 0; t < N; ++t) {
    const int w = what[static_cast<std::size_t>(t)];
    if (stages.empty() || stages.back().what != w)
      stages.push_back({t, t, w});
    else
      stages.back().last = t;
  }
  // Short runs join the run before (the first joins the one after).
  std::vector<ManipulationStage> merged;
  for (const ManipulationStage& st : stages) {
    const bool short_run = st.last - st.first + 1 < min_frames;
    if (!merged.empty() && (short_run || merged.back().last - merged.back().first + 1 < min_frames)) {
      if (!short_run && merged.back().last - merged.back().first + 1 < min_frames) merged.back().what = st.what;
      merged.back().last = st.last;
    } else {
      merged.push_back(st);
    }
  }
  // Neighbours that ended up alike are one stage.
  std::vector<ManipulationStage> out;
  for (const ManipulationStage& st : merged) {
    if (!out.empty() && out.back().what == st.what)
      out.back().last = st.last;
    else
      out.push_back(st);
  }
  return out;
}

at::Tensor stage_contact_targets(const at::Tensor& maps, const std::vector<ManipulationStage>& stages) {
  const bool batched = maps.dim() == 4;
  const at::Tensor m = batched ? maps : maps.unsqueeze(0);
  if (m.dim() != 4) throw Error("stage contact targets: need maps [S, N, 2, M], got " + c10::str(maps.sizes()));
  at::Tensor out = m.clone();
  for (const ManipulationStage& st : stages) {
    if (st.first < 0 || st.last >= m.size(1) || st.last < st.first)
      throw Error("stage contact targets: a stage [" + std::to_string(st.first) + ", " + std::to_string(st.last) +
                  "] outside the maps' " + std::to_string(m.size(1)) + " frames");
    const std::int64_t mid = (st.first + st.last) / 2;
    out.slice(1, st.first, st.last + 1).copy_(m.slice(1, mid, mid + 1).expand({m.size(0), st.last - st.first + 1, m.size(2), m.size(3)}));
  }
  return batched ? out : out[0];
}

at::Tensor stages_tensor(const std::vector<ManipulationStage>& stages) {
  at::Tensor t = at::empty({static_cast<std::int64_t>(stages.size()), 3}, at::kLong);
  for (std::size_t k = 0; k < stages.size(); ++k) {
    t[static_cast<std::int64_t>(k)][0] = stages[k].first;
    t[static_cast<std::int64_t>(k)][1] = stages[k].last;
    t[static_cast<std::int64_t>(k)][2] = stages[k].what;
  }
  return t;
}

std::vector<ManipulationStage> stages_from_tensor(const at::Tensor& t_in) {
  const at::Tensor t = t_in.to(at::kLong).contiguous();
  if (t.dim() != 2 || t.size(1) != 3) throw Error("manipulation stages: need [K, 3] int64, got " + c10::str(t_in.sizes()));
  std::vector<ManipulationStage> s;
  const std::int64_t* p = t.data_ptr<std::int64_t>();
  for (std::int64_t k = 0; k < t.size(0); ++k) s.push_back({p[3 * k], p[3 * k + 1], static_cast<int>(p[3 * k + 2])});
  return s;
}

}  // namespace bimart
