// export.sequence: the refined hands with the object states as a sequence file, which
// `bimart eval` reads (docs/formats.md, "Sequence").
#include <filesystem>

#include "core/io/sequence.h"
#include "core/pipeline/plugin.h"
#include "stages/exporter.h"

namespace bimart {
namespace {

class SequenceExport : public Exporter {
 public:
  static StageSpec spec() {
    return StageSpec::of<Exporter>("sequence", "the hands and object states as a sequence file (.npz)")
        .input<HandMotion>("hand_params", "the hands, world frame")
        .input<at::Tensor>("object_states", "[N, 7]")
        .input<double>("fps", "frames per second")
        .input<std::string>("object_path", "the object's folder or YAML (stored relative to the file)")
        .optional_input<at::Tensor>("contact_maps", "[N, 2, 1024] the contact maps that conditioned the motion (CM metric)")
        .optional_input<at::Tensor>("basis_hit_indices", "[N, 1024] the encoder's hit vertices, stored with contact_maps")
        .param("path", "out/sequence.npz", "file to write (folders are created)")
        .param("name", "", "sequence name stored in the file (default: the file's stem)");
  }
  explicit SequenceExport(const Params& p) : path_(p.string("path")), name_(p.string("name")) {
    if (path_.empty()) throw Error("path must not be empty");
  }
  void run(StageIO& io) override {
    namespace fs = std::filesystem;
    Sequence s;
    s.name = name_.empty() ? fs::path(path_).stem().string() : name_;
    s.fps = io.in<double>("fps");
    s.object_states = io.in<at::Tensor>("object_states");
    s.hands = io.in<HandMotion>("hand_params");
    s.hands.vertices = at::Tensor();
    if (io.has("contact_maps") != io.has("basis_hit_indices"))
      throw Error("export.sequence: wire contact_maps and basis_hit_indices together (or neither)");
    if (io.has("contact_maps")) {
      s.contact_maps = io.in<at::Tensor>("contact_maps");
      s.basis_hit_indices = io.in<at::Tensor>("basis_hit_indices");
    }
    fs::create_directories(fs::absolute(fs::path(path_)).parent_path());
    s.object = relative_object_path(io.in<std::string>("object_path"), path_);
    write_sequence(s, path_);
    io.out("path", path_);
  }

 private:
  std::string path_, name_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::SequenceExport)
