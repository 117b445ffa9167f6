#include "core/metrics/frame_report.h"

#include <fmt/format.h>

#include <ATen/ATen.h>

#include "core/hand/finger_separation.h"
#include "core/metrics/frame_depths.h"
#include "core/metrics/hand_plausibility.h"
#include "core/util/error.h"

namespace bimart {
std::vector<HandFrameRow> hand_frame_rows(const ObjectDistance& distance, const at::Tensor& states_in,
                                          const at::Tensor& vertices_in, const std::array<const HandModel*, 2>& models) {
  const at::Tensor states = states_in.to(at::kCPU, at::kDouble).contiguous();
  const at::Tensor v = vertices_in.to(at::kCPU, at::kDouble).contiguous();
  if (states.dim() != 2 || states.size(1) != 7) throw Error("object states must be [N, 7]");
  const std::int64_t N = states.size(0);
  if (v.dim() != 4 || v.size(0) != 2 || v.size(1) != N || v.size(3) != 3)
    throw Error("hand vertices must be [2, N, V, 3] with N = " + std::to_string(N));
  const std::int64_t V = v.size(2);
  for (const HandModel* m : models)
    if (m == nullptr || m->num_vertices() != V)
      throw Error("frame report: the hand model has another vertex count than the hands (" + std::to_string(V) + ")");
  std::vector<HandFrameRow> rows;
  rows.reserve(static_cast<size_t>(2 * N));
  for (std::int64_t t = 0; t < N; ++t) {
    const ObjectState state = ObjectState::from_row(states.data_ptr<double>() + 7 * t);
    for (int h = 0; h < 2; ++h) {
      const HandModel& m = *models[static_cast<size_t>(h)];
      const Points3 pts = Eigen::Map<const Points3>(v.data_ptr<double>() + ((h * N + t) * V) * 3, V, 3);
      HandFrameRow r;
      r.frame = t;
      r.hand = h;
      r.depth = distance.max_signed_distance(state, pts);
      if (r.depth > 0) {
        const Eigen::Vector3d centre = pts.colwise().mean().transpose();
        double deepest = -1;
        for (const auto& [i, q] : distance.near_surface(state, pts, 0.0)) {
          if (q.signed_distance <= deepest) continue;
          deepest = q.signed_distance;
          r.vertex = i;
          r.part = q.part == ObjectPart::Top ? "top" : "bottom";
          r.through = q.normal.dot(centre - q.closest) < 0;
        }
        if (r.vertex >= 0) r.region = HandModel::kJointNames[static_cast<size_t>(skinning_joint(m, r.vertex))];
      }
      r.cavity = distance.max_cavity_depth(state, pts, kCavityFloor);
      const Eigen::Matrix<double, 16, 3> J = m.j_regressor * pts;
      Eigen::Matrix<double, 5, 3> tips;
      for (int f = 0; f < 5; ++f) tips.row(f) = pts.row(m.fingertips[static_cast<size_t>(f)]);
      r.implausible = implausibility(J, tips, h);
      double j3[16][3], t3[5][3];
      for (int j = 0; j < 16; ++j)
        for (int k = 0; k < 3; ++k) j3[j][k] = J(j, k);
      for (int f = 0; f < 5; ++f)
        for (int k = 0; k < 3; ++k) t3[f][k] = tips(f, k);
      r.closest_fingers = closest_fingers(j3, t3);
      rows.push_back(std::move(r));
    }
  }
  return rows;
}

void write_frame_rows_csv(std::ostream& out, const std::string& sequence, const std::vector<HandFrameRow>& rows,
                          bool with_header) {
  if (with_header) out << "sequence,frame,hand,depth_mm,vertex,region,part,through,cavity_mm,closest_fingers_mm,implausible\n";
  for (const auto& r : rows)
    out << fmt::format("{},{},{},{:.2f},{},{},{},{},{:.2f},{:.2f},\"{}\"\n", sequence, r.frame, r.hand == 0 ? "left" : "right",
                       1e3 * r.depth, r.vertex, r.region, r.part, r.through ? 1 : 0, 1e3 * r.cavity, 1e3 * r.closest_fingers, r.implausible);
}

}  // namespace bimart
