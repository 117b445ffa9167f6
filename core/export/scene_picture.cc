#include "core/export/scene_picture.h"

#include <fmt/format.h>

#include <ATen/ATen.h>

#include "core/hand/lbs.h"
#include "core/object/object_state.h"
#include "core/util/error.h"

namespace bimart {

Image render_sequence_frames(const SceneSource& src, const std::vector<std::int64_t>& frames, int size, int columns) {
  const Sequence& s = src.sequence;
  const std::int64_t n = s.num_frames();
  if (frames.empty()) throw Error("render: no frames given");
  if (size < 16) throw Error("render: the picture size must be at least 16 pixels");
  const at::Tensor states = s.object_states.to(at::kDouble).contiguous();
  const SceneColors colors;
  // Meshes of every chosen frame first (render items point into them), then the items.
  std::vector<TriangleMesh> meshes;
  meshes.reserve(4 * frames.size());
  for (std::int64_t t : frames) {
    if (t < 0 || t >= n)
      throw Error(fmt::format("render: frame {} is out of range: {} has {} frames (0..{})", t,
                              src.path.empty() ? s.name : src.path, n, n - 1));
    const PosedObject obj = pose_world(src.object, ObjectState::from_row(states[t].data_ptr<double>()));
    meshes.push_back(TriangleMesh{obj.top, src.object.top.faces});
    meshes.push_back(TriangleMesh{obj.bottom, src.object.bottom.faces});
    for (int h = 0; h < 2; ++h) {
      const HandParams& p = s.hands.hands[h];
      const at::Tensor rot = p.rot[t].to(at::kDouble).contiguous(), pose = p.pose[t].to(at::kDouble).contiguous(),
                       trans = p.trans[t].to(at::kDouble).contiguous(), beta = p.shape.to(at::kDouble).contiguous();
      LbsResult<double> r;
      lbs(*src.models()[h], rot.data_ptr<double>(), pose.data_ptr<double>(), trans.data_ptr<double>(),
          beta.data_ptr<double>(), &r);
      meshes.push_back(TriangleMesh{r.vertices, src.models()[h]->faces});
    }
  }
  auto items_of = [&](size_t i) {
    return std::vector<RenderItem>{{&meshes[4 * i], colors.top},
                                   {&meshes[4 * i + 1], colors.bottom},
                                   {&meshes[4 * i + 2], colors.left},
                                   {&meshes[4 * i + 3], colors.right}};
  };
  std::vector<RenderItem> all;
  for (size_t i = 0; i < frames.size(); ++i)
    for (const RenderItem& it : items_of(i)) all.push_back(it);
  const Camera camera = frame_items(all, Eigen::Vector3d(0.35, -0.6, -1.0).normalized(), 35);
  std::vector<Image> images;
  for (size_t i = 0; i < frames.size(); ++i) images.push_back(render(items_of(i), camera, size, size));
  return tile(images, columns > 0 ? columns : static_cast<int>(images.size()));
}

}  // namespace bimart
