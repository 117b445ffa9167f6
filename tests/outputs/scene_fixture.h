// Test scenes for the output tests: a procedural box, hands moving near it, hand models
// with pose correctives (the shipped hands have none), contact maps measured from the hands.
#pragma once

#include <array>
#include <cmath>
#include <string>

#include <ATen/ATen.h>

#include "core/export/scene_source.h"
#include "core/features/contact_map.h"
#include "core/geometry/triangle_mesh.h"
#include "core/hand/lbs.h"
#include "core/object/families/families.h"
#include "core/object/object_state.h"
#include "core/util/data_path.h"

namespace bimart::test {

// The shipped hand with made-up correctives: column (joint j, entry e) moves each vertex along
// its normal by up to 4.5 mm per unit of (R - I), in proportion to its weight on joint j.
inline HandModel with_correctives(HandModel m) {
  TriangleMesh mesh{m.v_template, m.faces};
  const Eigen::MatrixX3d n = vertex_normals(mesh);
  for (int c = 0; c < HandModel::kNumPoseFeatures; ++c) {
    const int j = 1 + c / 9, e = c % 9;
    const double sign = (e - 4) + 0.5;  // never zero: every column is a target
    for (int v = 0; v < m.num_vertices(); ++v)
      for (int k = 0; k < 3; ++k) m.posedirs(3 * v + k, c) = 0.001 * sign * m.weights(v, j) * n(v, k);
  }
  return m;
}

inline std::array<HandModel, 2> shipped_hand_models() {
  return load_hand_models(find_data_file("models/hand/mano_left.npz"), find_data_file("models/hand/mano_right.npz"));
}

// N frames: the lid opens, the object turns and moves; the hands hover near it, curling.
inline Sequence test_sequence(std::int64_t n, const std::array<const HandModel*, 2>& models, double fps = 30) {
  Sequence s;
  s.name = "test_scene";
  s.object = "box";
  s.category = "box";
  s.kind = "use";
  s.fps = fps;
  s.object_states = at::zeros({n, 7}, at::kFloat);
  for (std::int64_t t = 0; t < n; ++t) {
    const double u = double(t) / std::max<std::int64_t>(1, n - 1);
    const float row[7] = {float(1.2 * u), float(0.3 * u), float(0.8 * u - 0.2), float(0.1 * std::sin(3 * u)),
                          float(0.1 * u), float(0.12 + 0.05 * u), float(-0.05 * u)};
    for (int k = 0; k < 7; ++k) s.object_states[t][k] = row[k];
  }
  for (int h = 0; h < 2; ++h) {
    HandParams& p = s.hands.hands[h];
    p.rot = at::zeros({n, 3});
    p.pose = at::zeros({n, 45});
    p.trans = at::zeros({n, 3});
    p.shape = at::linspace(-0.8, 0.8, 10) * (h == 0 ? 1.0 : -0.6);
    for (std::int64_t t = 0; t < n; ++t) {
      const double u = double(t) / std::max<std::int64_t>(1, n - 1);
      p.rot[t][0] = -1.2 + 0.5 * u;
      p.rot[t][1] = (h == 0 ? 0.6 : -0.6) + 0.3 * std::sin(4 * u);
      p.rot[t][2] = 0.2 * u;
      for (int i = 0; i < 45; ++i) p.pose[t][i] = models[h]->hands_mean[i] * (0.4 + 0.8 * u) + 0.1 * std::sin(i + 5 * u);
      p.trans[t][0] = (h == 0 ? -0.25 : 0.05) + 0.1 * u;
      p.trans[t][1] = 0.15;
      p.trans[t][2] = 0.05 - 0.05 * u;
    }
  }
  return s;
}

// Posed vertices [V, 3] of hand h at frame t, with bimart's own LBS.
inline LbsResult<double> posed_hand(const Sequence& s, const HandModel& m, int h, std::int64_t t) {
  const HandParams& p = s.hands.hands[h];
  const at::Tensor rot = p.rot[t].to(at::kDouble).contiguous(), pose = p.pose[t].to(at::kDouble).contiguous(),
                   trans = p.trans[t].to(at::kDouble).contiguous(), beta = p.shape.to(at::kDouble).contiguous();
  LbsResult<double> r;
  lbs(m, rot.data_ptr<double>(), pose.data_ptr<double>(), trans.data_ptr<double>(), beta.data_ptr<double>(), &r);
  return r;
}

// Contact maps measured from the hands: 1024 object vertices (every k-th of [top; bottom]),
// each one's distance to the nearest vertex of each hand, world frame.
inline void add_contact_maps(Sequence& s, const ArticulatedObject& object, const std::array<const HandModel*, 2>& models) {
  const std::int64_t n = s.num_frames();
  const std::int64_t vt = object.top.num_vertices(), vb = object.bottom.num_vertices();
  at::Tensor ids = at::zeros({n, 1024}, at::kLong), objp = at::zeros({n, 1024, 3}, at::kDouble);
  at::Tensor hands = at::zeros({2, n, models[0]->num_vertices(), 3}, at::kDouble);
  const at::Tensor states = s.object_states.to(at::kDouble).contiguous();
  for (std::int64_t t = 0; t < n; ++t) {
    const PosedObject o = pose_world(object, ObjectState::from_row(states[t].data_ptr<double>()));
    for (int k = 0; k < 1024; ++k) {
      const std::int64_t v = (k * (vt + vb)) / 1024;
      ids[t][k] = v;
      const auto row = v < vt ? o.top.row(v) : o.bottom.row(v - vt);
      for (int c = 0; c < 3; ++c) objp[t][k][c] = row[c];
    }
    for (int h = 0; h < 2; ++h) {
      const LbsResult<double> r = posed_hand(s, *models[h], h, t);
      hands[h][t].copy_(at::from_blob(const_cast<double*>(r.vertices.data()), {r.vertices.rows(), 3}, at::kDouble));
    }
  }
  s.contact_maps = contact_maps(objp, hands).to(at::kFloat);
  s.basis_hit_indices = ids;
}

}  // namespace bimart::test
