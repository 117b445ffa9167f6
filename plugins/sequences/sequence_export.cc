// export.sequence: the refined hands with the object states as a sequence file, which
// `bimart eval` reads (docs/formats.md, "Sequence"); one file per sample with a {sample}
// path (stages/samples.h). Without an object_path the object is saved beside the files.
#include <filesystem>

#include "core/io/sequence.h"
#include "core/object/object_io.h"
#include "core/pipeline/plugin.h"
#include "core/util/log.h"
#include "stages/exporter.h"
#include "stages/samples.h"

namespace bimart {
namespace {

class SequenceExport : public Exporter {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<Exporter>("sequence", "the hands and object states as a sequence file (.npz)");
    s.input<HandMotion>("hand_params", "the hands, world frame")
        .input<at::Tensor>("object_states", "[N, 7]")
        .input<double>("fps", "frames per second")
        .optional_input<std::string>("object_path",
                                     "the object's folder or YAML (stored relative to the file); when absent, "
                                     "`object` is saved to <folder of path>/object/")
        .optional_input<ArticulatedObject>("object", "the object, canonical frame (saved when there is no object_path)")
        .optional_input<at::Tensor>("contact_maps", "[N, 2, 1024] the contact maps that conditioned the motion (CM metric)")
        .optional_input<at::Tensor>("basis_hit_indices", "[N, 1024] the encoder's hit vertices, stored when contact_maps is wired too")
        .param("path", "out/sequence.npz", "file to write (folders are created); {sample} in it: one file per sample")
        .param("name", "", "sequence name stored in the file (default: the file's stem)");
    declare_sample_ports(s);
    return s;
  }
  explicit SequenceExport(const Params& p) : path_(p.string("path")), name_(p.string("name")) {
    if (path_.empty()) throw Error("path must not be empty");
    sample_path(path_, 0);  // a bad placeholder fails before any work
  }
  void run(StageIO& io) override {
    namespace fs = std::filesystem;
    std::vector<StageSample> samples = stage_samples(io);
    if (!has_sample_placeholder(path_) && samples.size() > 1) {
      log::warn("export.sequence: {} samples, but path '{}' has no {{sample}}: writing sample 0 only", samples.size(),
                path_);
      samples.resize(1);
    }
    // Every file is built first, so a bad input writes none of them.
    std::vector<std::pair<Sequence, std::string>> files;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const std::string path = sample_path(path_, k);
      Sequence s;
      s.name = name_.empty() ? fs::path(path).stem().string() : sample_path(name_, k);
      s.fps = io.in<double>("fps");
      s.object_states = io.in<at::Tensor>("object_states");
      s.hands = *samples[k].hands;
      s.hands.vertices = at::Tensor();
      // Stored when both are wired (an encoder alone wires the hit indices by name).
      if (samples[k].contact_maps.defined() && io.has("basis_hit_indices")) {
        s.contact_maps = samples[k].contact_maps.contiguous();
        s.basis_hit_indices = io.in<at::Tensor>("basis_hit_indices");
      }
      s.object = "object";  // set below; validated here with the rest
      s.validate();
      files.emplace_back(std::move(s), path);
    }
    std::string object_path;
    if (io.has("object_path")) {
      object_path = io.in<std::string>("object_path");
    } else if (io.has("object")) {
      object_path = (fs::absolute(fs::path(files[0].second)).parent_path() / "object").string();
      save_object(io.in<ArticulatedObject>("object"), object_path);
    } else {
      throw Error("neither object_path nor object is wired: the file must say which object it uses");
    }
    std::vector<std::string> written;
    for (auto& [s, path] : files) {
      fs::create_directories(fs::absolute(fs::path(path)).parent_path());
      s.object = relative_object_path(object_path, path);
      write_sequence(s, path);
      written.push_back(path);
    }
    io.out("path", has_sample_placeholder(path_) ? fs::path(written[0]).parent_path().string() : written[0]);
    io.out("paths", written);
  }

 private:
  std::string path_, name_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::SequenceExport)
