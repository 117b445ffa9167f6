// trajectory.file: the object and 7-DoF trajectory of a file — per-frame CSV, YAML or
// sequence .npz, or YAML keyframes (core/trajectory/, docs/trajectories.md). Everything is
// read and checked against the object when the stage is created, before any stage runs.
#include <ATen/ATen.h>

#include "core/pipeline/plugin.h"
#include "core/trajectory/trajectory.h"
#include "core/trajectory/trajectory_object.h"
#include "core/trajectory/validation.h"
#include "stages/trajectory_source.h"

namespace bimart {
namespace {

class FileTrajectory : public TrajectorySource {
 public:
  static StageSpec spec() {
    return StageSpec::of<TrajectorySource>(
               "file", "a trajectory file: per-frame .csv, .yaml or .npz, or YAML keyframes (docs/trajectories.md)")
        .output<std::string>("object_path", "the object's folder or YAML, absolute")
        .param("path", "", "trajectory file: .csv, .yaml/.yml (frames: or keys:), .npz sequence")
        .param("object", "",
               "object folder or object.yaml (bimart object make / import) or ARCTIC template folder, relative to "
               "the trajectory file's folder; replaces the file's object")
        .param("category", "", "procedural object category (bimart object list), with seed; replaces the file's object")
        .param("seed", 0, "seed of the procedural object (with category)")
        .param("fps", 0.0,
               "frames per second: keyframes are sampled at it, a per-frame file plays at it (0: the file's, else 30)")
        .param("object_dir", "",
               "folder a procedural object is written to, for exporters (default: ~/.cache/bimart/objects/"
               "CATEGORY_SEED)");
  }

  explicit FileTrajectory(const Params& p) {
    const std::string& path = p.string("path");
    if (path.empty()) throw Error("path: give a trajectory file (.csv, .yaml or .npz)");
    ObjectReference chosen;
    chosen.path = p.string("object");
    chosen.category = p.string("category");
    chosen.seed = p.integer("seed");
    if (!chosen.path.empty() && !chosen.category.empty()) throw Error("give either object or category, not both");
    trajectory_ = read_trajectory(path, p.number("fps"));
    object_ = resolve_trajectory_object(chosen, trajectory_.object, path, p.string("object_dir"));
    validate_trajectory(trajectory_, object_.object);
  }

  void run(StageIO& io) override {
    save_trajectory_object(object_);
    const at::Tensor states =
        at::from_blob(trajectory_.states.data(), {trajectory_.num_frames(), 7}, at::kDouble).to(at::kFloat).contiguous();
    io.out("object", object_.object);
    io.out("object_states", states);
    io.out("fps", trajectory_.fps);
    io.out("object_path", object_.path);
  }

 private:
  Trajectory trajectory_;
  TrajectoryObject object_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::FileTrajectory)
