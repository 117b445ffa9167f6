// export.gltf: the hands and the object as a binary glTF scene (core/export/gltf_scene.h);
// one file per sample with a {sample} path (stages/samples.h).
#include <filesystem>

#include "core/export/gltf_scene.h"
#include "core/util/atomic_file.h"
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
    s.param("path", "out/scene.glb", "file to write (folders are created); {sample} in it: one file per sample")
        .param("correctives", true, "pose correctives as morph targets (off: lighter file, skinning only)");
    return s;
  }
  explicit GltfExport(const Params& p)
      : path_(p.string("path")), name_(p.string("name")), correctives_(p.boolean("correctives")),
        hands_(load_export_hands(p.string("mano_left"), p.string("mano_right"))) {
    if (path_.empty()) throw Error("path must not be empty");
    sample_path(path_, 0);  // a bad placeholder fails before any work
  }
  void run(StageIO& io) override {
    std::vector<StageSample> samples = stage_samples(io);
    if (!has_sample_placeholder(path_) && samples.size() > 1) {
      log::warn("export.gltf: {} samples, but path '{}' has no {{sample}}: writing sample 0 only", samples.size(), path_);
      samples.resize(1);
    }
    GltfOptions o;
    o.correctives = correctives_;
    // Every scene is built first, so a bad input writes none of them.
    std::vector<std::pair<std::string, std::string>> files;  // path, bytes
    GltfSummary sum;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const std::string path = sample_path(path_, k);
      const std::string name = name_.empty() ? std::filesystem::path(path).stem().string() : sample_path(name_, k);
      const SceneSource src = outputs_plugin::scene_from_inputs(io, hands_, name, samples[k]);
      files.emplace_back(path, build_glb(src.sequence, src.object, src.models(), o, &sum));
    }
    std::vector<std::string> written;
    for (const auto& [path, bytes] : files) {
      write_file_atomically(path, [&](std::ostream& out) { out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); });
      log::info("{}: {} frames, {} + {} corrective morph targets, {:.2f} MB", path, sum.frames, sum.morph_targets[0],
                sum.morph_targets[1], bytes.size() / 1e6);
      written.push_back(path);
    }
    io.out("path", has_sample_placeholder(path_) ? std::filesystem::path(written[0]).parent_path().string() : written[0]);
    io.out("paths", written);
  }

 private:
  std::string path_, name_;
  bool correctives_;
  std::shared_ptr<const std::array<HandModel, 2>> hands_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::GltfExport)
