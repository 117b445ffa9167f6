// export.html: the viewer page (core/export/viewer_page.h), with every sample of the run
// (stages/samples.h) on one page.
#include <filesystem>

#include "core/directing/hand_constraints.h"
#include "core/export/gltf_scene.h"
#include "core/export/viewer_page.h"
#include "core/util/log.h"
#include "plugins/outputs/stage_inputs.h"
#include "stages/exporter.h"

namespace bimart {
namespace {

class HtmlExport : public Exporter {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<Exporter>("html", "a self-contained viewer page (three.js, no network)");
    outputs_plugin::declare_scene_inputs(s);
    s.optional_input<HandConstraints>("hand_constraints", "a directed run's constraints, marked on the page (docs/directing.md)");
    s.param("path", "out/viewer.html", "file to write (folders are created)")
        .param("correctives", true, "pose correctives as morph targets in the embedded scene");
    return s;
  }
  explicit HtmlExport(const Params& p)
      : path_(p.string("path")), name_(p.string("name")), correctives_(p.boolean("correctives")),
        hands_(load_export_hands(p.string("mano_left"), p.string("mano_right"))) {
    if (path_.empty()) throw Error("path must not be empty");
    viewer_bundle_path();  // fails before any work when the script is missing
  }
  void run(StageIO& io) override {
    const std::string name = name_.empty() ? std::filesystem::path(path_).stem().string() : name_;
    const std::vector<StageSample> samples = stage_samples(io);
    GltfOptions o;
    o.correctives = correctives_;
    std::vector<ViewerSample> pages;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const std::string sample_name = samples.size() == 1 ? name : "sample " + std::to_string(k);
      const SceneSource src = outputs_plugin::scene_from_inputs(io, hands_, sample_name, samples[k]);
      ViewerSample sample;
      sample.name = sample_name;
      sample.fps = src.sequence.fps;
      sample.frames = src.sequence.num_frames();
      sample.glb = build_glb(src.sequence, src.object, src.models(), o);
      sample.contacts = viewer_contacts(src.sequence);
      sample.top_vertices = src.object.top.num_vertices();
      if (io.has("hand_constraints")) sample.marks = viewer_marks(io.in<HandConstraints>("hand_constraints"), src);
      pages.push_back(std::move(sample));
    }
    const auto bytes = write_viewer_page(pages, name, path_);
    log::info("{}: {} sample{}, {:.2f} MB", path_, pages.size(), pages.size() == 1 ? "" : "s", bytes / 1e6);
    io.out("path", path_);
    io.out("paths", std::vector<std::string>{path_});
  }

 private:
  std::string path_, name_;
  bool correctives_;
  std::shared_ptr<const std::array<HandModel, 2>> hands_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::HtmlExport)
