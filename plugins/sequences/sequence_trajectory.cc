// trajectory.sequence: the object, states and frame rate of a sequence file, plus its
// ground-truth hands (for motion.ground_truth and for comparisons).
#include <filesystem>

#include "core/io/sequence.h"
#include "core/object/canonical_frame.h"
#include "core/object/object_io.h"
#include "core/pipeline/plugin.h"
#include "core/trajectory/trajectory_object.h"
#include "stages/trajectory_source.h"

namespace bimart {
namespace {

class SequenceTrajectory : public TrajectorySource {
 public:
  static StageSpec spec() {
    return StageSpec::of<TrajectorySource>("sequence", "the object and 7-DoF trajectory of a sequence file (.npz)")
        .output<HandMotion>("ground_truth", "the file's hands, world frame, ARCTIC layout")
        .output<std::string>("object_path", "the object's folder or YAML, absolute (a canonical copy when the file's object is turned)")
        .param("path", "", "sequence file (docs/formats.md, \"Sequence\")");
  }
  explicit SequenceTrajectory(const Params& p) : path_(p.string("path")) {
    if (path_.empty()) throw Error("path: give a sequence file");
  }
  void run(StageIO& io) override {
    const Sequence s = read_sequence(path_);
    TrajectoryObject o;
    o.path = std::filesystem::absolute(resolve_object_path(s, path_)).string();
    o.object = load_object(o.path);
    // The object in its canonical pose about the hinge, the states moved with it, so that
    // the world geometry is the file's (trajectory.file does the same).
    make_canonical(o);
    save_trajectory_object(o);
    io.out("object", o.object);
    io.out("object_states",
           (o.moved ? canonical_states(s.object_states, o.from_source) : s.object_states).to(at::kFloat).contiguous());
    io.out("fps", s.fps);
    io.out("ground_truth", s.hands);
    io.out("object_path", o.path);
  }

 private:
  std::string path_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::SequenceTrajectory)
