#include "core/export/scene_source.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>

#include <ATen/ATen.h>

#include "core/hand/lbs.h"
#include "core/object/object_io.h"
#include "core/util/data_path.h"
#include "core/util/error.h"

namespace bimart {

std::shared_ptr<const std::array<HandModel, 2>> load_export_hands(const std::string& mano_left,
                                                                  const std::string& mano_right) {
  if (mano_left.empty() != mano_right.empty())
    throw Error("give both hand models (--mano-left and --mano-right), or neither for the shipped hands");
  const std::string left = mano_left.empty() ? find_data_file("models/hand/mano_left.npz") : mano_left;
  const std::string right = mano_right.empty() ? find_data_file("models/hand/mano_right.npz") : mano_right;
  return std::make_shared<const std::array<HandModel, 2>>(load_hand_models(left, right));
}

void check_hands_fit(const Sequence& s, const std::array<const HandModel*, 2>& models, const std::string& where) {
  if (!s.hands.has_vertices()) return;
  const at::Tensor verts = s.hands.vertices.to(at::kDouble).contiguous();
  const std::int64_t n = s.num_frames();
  for (int h = 0; h < 2; ++h) {
    const HandModel& m = *models[h];
    const char* side = h == 0 ? "left" : "right";
    if (verts.size(2) != m.num_vertices())
      throw Error(fmt::format("{}: hand_vertices has {} vertices per hand, but the {} hand model has {}: the "
                              "sequence was made with another hand model; give its models "
                              "(--mano-left/--mano-right, or the stage's mano_left/mano_right)",
                              where, verts.size(2), side, m.num_vertices()));
    const HandParams& p = s.hands.hands[h];
    const at::Tensor rot = p.rot.to(at::kDouble).contiguous(), pose = p.pose.to(at::kDouble).contiguous(),
                     trans = p.trans.to(at::kDouble).contiguous(), beta = p.shape.to(at::kDouble).contiguous();
    for (std::int64_t t : {std::int64_t{0}, n / 2, n - 1}) {
      LbsResult<double> r;
      lbs(m, rot[t].data_ptr<double>(), pose[t].data_ptr<double>(), trans[t].data_ptr<double>(),
          beta.data_ptr<double>(), &r);
      const double* stored = verts[h][t].data_ptr<double>();
      double worst = 0;
      for (int v = 0; v < m.num_vertices(); ++v)
        for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(r.vertices(v, k) - stored[3 * v + k]));
      if (worst > 1e-3)
        throw Error(fmt::format("{}: the {} hand model does not reproduce the stored hand_vertices (frame {}: "
                                "{:.1f} mm off): the sequence was made with another hand model; give its "
                                "models (--mano-left/--mano-right)",
                                where, side, t, 1e3 * worst));
    }
  }
}

SceneSource load_scene_source(const std::string& sequence_path,
                              std::shared_ptr<const std::array<HandModel, 2>> hands) {
  SceneSource src;
  src.path = sequence_path;
  src.sequence = read_sequence(sequence_path);
  if (src.sequence.num_frames() < 1) throw Error(sequence_path + ": the sequence has no frames");
  const std::string object_path = resolve_object_path(src.sequence, sequence_path);
  try {
    src.object = load_object(object_path);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: cannot load its object '{}': {}", sequence_path, src.sequence.object, e.what()));
  }
  src.hands = std::move(hands);
  check_hands_fit(src.sequence, src.models(), sequence_path);
  if (src.sequence.name.empty()) src.sequence.name = std::filesystem::path(sequence_path).stem().string();
  return src;
}

}  // namespace bimart
