#include "core/synth/dataset_check.h"

#include <algorithm>
#include <memory>
#include <thread>

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include "core/data/manifest.h"
#include "core/geometry/mesh_distance.h"
#include "core/hand/hand_model.h"
#include "core/io/sequence.h"
#include "core/util/error.h"
#include "core/metrics/articulation.h"
#include "core/metrics/contact.h"
#include "core/metrics/frame_depths.h"
#include "core/metrics/hand_vertices.h"
#include "core/object/object_cache.h"
#include "core/util/data_path.h"
#include "core/util/parallel.h"
#include "core/util/progress.h"

namespace bimart {
namespace {

Points3 frame_points(const at::Tensor& v, int h, int64_t t) {  // v [2, N, V, 3] double
  const at::Tensor f = v[h][t].contiguous();
  return Eigen::Map<const Points3>(f.data_ptr<double>(), f.size(0), 3);
}

}  // namespace

DatasetCheck check_dataset(const std::string& folder, const std::string& split, int threads, bool progress,
                           int frame_step, const std::string& mano_left, const std::string& mano_right) {
  const DatasetManifest m = read_manifest(folder);
  const std::vector<std::string> files = split_files(m, folder, split);
  const bool own = !mano_left.empty() || !mano_right.empty();
  if (own) set_posing_hand_models(mano_left, mano_right);  // hand_vertices poses with them
  const std::array<HandModel, 2> model{
      load_hand_model(own ? mano_left : find_data_file("models/hand/mano_left.npz")),
      load_hand_model(own ? mano_right : find_data_file("models/hand/mano_right.npz"))};
  threads = resolve_threads(threads);
  const int saved = at::get_num_threads();
  at::set_num_threads(1);

  ObjectCache objects;
  std::vector<DatasetCheck> parts(files.size());
  {
    ProgressBar bar("checking " + split, files.size(), progress);
    parallel_for(files.size(), threads, [&](size_t i) {
      const Sequence s = read_sequence(files[i]);
      const std::string path = resolve_object_path(s, files[i]);
      std::shared_ptr<const ObjectCache::Entry> obj;
      try {
        obj = objects.get(path);
      } catch (const Error& e) {
        throw Error(files[i] + ": its object '" + s.object + "' (" + path + "): " + e.what());
      }
      DatasetCheck& c = parts[i];
      c.sequences = 1;
      const at::Tensor v = hand_vertices(s.hands).to(at::kDouble).contiguous();
      const int64_t n = s.num_frames();
      std::array<FrameDepths, 2> depth;  // per hand
      for (int h = 0; h < 2; ++h) depth[h] = frame_depths(*obj->distance, s.object_states, at::stack({v[h], v[h]}));
      const std::vector<bool> moving = object_moving_frames(obj->object, s.object_states);
      for (int64_t t = 0; t < n; ++t) {
        if (!moving[static_cast<size_t>(t)]) continue;
        ++c.moving_frames;
        c.both_touching += depth[0].whole(static_cast<size_t>(t)) > -kContactDistance &&
                           depth[1].whole(static_cast<size_t>(t)) > -kContactDistance;
      }
      if (s.kind == "use") {
        const std::vector<bool> turning = angle_changing_frames(s.object_states);
        std::array<int, 2> on_top{};
        bool any = false;
        for (int64_t t = 0; t < n; ++t) {
          if (!turning[static_cast<size_t>(t)]) continue;
          any = true;
          for (int h = 0; h < 2; ++h) on_top[h] += depth[h].top[static_cast<size_t>(t)] > -kContactDistance;
        }
        if (any) {
          c.use_sequences = 1;
          c.left_drives = on_top[0] > on_top[1];
        }
      }
      for (int64_t t = 0; t < n; t += std::max(1, frame_step)) {
        for (int h = 0; h < 2; ++h) {
          const TriangleMesh mesh{frame_points(v, h, t), model[h].faces};
          const double d = MeshDistance(mesh).max_signed_distance(frame_points(v, 1 - h, t));
          if (d > c.hand_interpenetration) c.hand_interpenetration = d, c.deepest_sequence = s.name;
        }
      }
      bar.step();
    });
  }
  at::set_num_threads(saved);
  DatasetCheck out;
  for (const DatasetCheck& c : parts) {
    out.sequences += c.sequences;
    out.moving_frames += c.moving_frames;
    out.both_touching += c.both_touching;
    out.use_sequences += c.use_sequences;
    out.left_drives += c.left_drives;
    if (c.hand_interpenetration > out.hand_interpenetration)
      out.hand_interpenetration = c.hand_interpenetration, out.deepest_sequence = c.deepest_sequence;
  }
  return out;
}

}  // namespace bimart
