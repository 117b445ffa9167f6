// export.gltf: the hands and the object as a binary glTF scene (core/export/gltf_scene.h).
#include <filesystem>

#include "core/export/gltf_scene.h"
#include "core/util/log.h"
#include "plugins/outputs/stage_inputs.h"
#include "stages/exporter.h"

namespace bimart {
namespace {

class GltfExport : public Exporter {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<Exporter>("gltf", "the hands (skinned, MANO skeleton) and the object as a .glb scene");
    outputs_plugin::declare_scene_inputs(s);
    s.param("path", "out/scene.glb", "file to write (folders are created)")
        .param("correctives", true, "pose correctives as morph targets (off: lighter file, skinning only)");
    return s;
  }
  explicit GltfExport(const Params& p)
      : path_(p.string("path")), name_(p.string("name")), correctives_(p.boolean("correctives")),
        hands_(load_export_hands(p.string("mano_left"), p.string("mano_right"))) {
    if (path_.empty()) throw Error("path must not be empty");
  }
  void run(StageIO& io) override {
    const std::string name = name_.empty() ? std::filesystem::path(path_).stem().string() : name_;
    const SceneSource src = outputs_plugin::scene_from_inputs(io, hands_, name);
    GltfOptions o;
    o.correctives = correctives_;
    const GltfSummary sum = write_glb(src.sequence, src.object, src.models(), path_, o);
    log::info("{}: {} frames, {} + {} corrective morph targets", path_, sum.frames, sum.morph_targets[0],
              sum.morph_targets[1]);
    io.out("path", path_);
  }

 private:
  std::string path_, name_;
  bool correctives_;
  std::shared_ptr<const std::array<HandModel, 2>> hands_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::GltfExport)
