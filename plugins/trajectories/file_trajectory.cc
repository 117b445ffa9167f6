// trajectory.file: the object and 7-DoF trajectory of a file — per-frame CSV, YAML or
// sequence .npz, or YAML keyframes (core/trajectory/, docs/trajectories.md). Everything is
// read and checked against the object when the stage is created, before any stage runs.
#include <ATen/ATen.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <filesystem>

#include "core/directing/hand_constraints.h"
#include "core/util/log.h"

#include "core/object/canonical_frame.h"
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
        .output<HandConstraints>("hand_constraints",
                                 "what the file's `hands:` block and the `hands` parameter ask of the hands "
                                 "(docs/directing.md); empty when nothing")
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
               "CATEGORY_SEED)")
        .yaml_param("hands",
               "more hand constraints (docs/directing.md): a YAML file with a `hands:` block, or the block's value "
               "inline, e.g. '{right: [{frames: [0, 40], part: top}]}'; added to the trajectory file's own")
        .param("redraw", std::vector<std::int64_t>{},
               "[first, last] (last -1: the last frame): the trajectory file is an earlier sample (.npz); redraw these frames and keep the "
               "others exactly (bimart edit, docs/directing.md); empty: off")
        .param("keep_contacts", false,
               "with an earlier sample as the trajectory: keep its contact maps everywhere, redraw the motion "
               "(over `redraw`, else every frame)")
        .param("redraw_blend", 8, "frames over which a redrawn stretch fades in from the kept frames at each join");
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
    hands_ = read_hand_constraints(path, trajectory_);
    if (const std::string& more = p.string("hands"); !more.empty()) {
      const bool inline_text = more.find_first_of("{[:\n") != std::string::npos;
      merge_hand_constraints(hands_, inline_text ? parse_hand_constraints(more, "parameter hands", "", trajectory_)
                                                 : read_hand_constraints(more, trajectory_, true));
    }
    read_redraw(p, path);
    // What the models see: the object in its canonical pose about the hinge, the states and
    // the object-frame regions moved with it (the world geometry is unchanged).
    make_canonical(object_);
    if (object_.moved) {
      log::info("trajectory.file: the object turned to its canonical pose about the hinge ({:.1f} deg){}",
                Eigen::AngleAxisd(object_.from_source.linear()).angle() * 180 / M_PI,
                object_.canonical_copy ? "; its canonical copy: " + object_.path : "");
      for (ContactConstraint& c : hands_.contacts)
        if (c.region) c.region->point = object_.from_source * c.region->point;
    }
    if (!hands_.empty()) log::info("trajectory.file: hands directed: {}", hands_.describe());
  }

  void run(StageIO& io) override {
    save_trajectory_object(object_);
    at::Tensor states = at::from_blob(trajectory_.states.data(), {trajectory_.num_frames(), 7}, at::kDouble);
    if (object_.moved) states = canonical_states(states, object_.from_source);
    states = states.to(at::kFloat).contiguous();
    io.out("object", object_.object);
    io.out("object_states", states);
    io.out("fps", trajectory_.fps);
    io.out("object_path", object_.path);
    io.out("hand_constraints", hands_);
  }

 private:
  void read_redraw(const Params& p, const std::string& path) {
    const auto& range = p.integers("redraw");
    const bool keep_contacts = p.boolean("keep_contacts");
    if (range.empty() && !keep_contacts) return;
    if (std::filesystem::path(path).extension() != ".npz")
      throw Error("redraw and keep_contacts need an earlier sample (.npz) as the trajectory file, got " + path);
    const std::int64_t n = trajectory_.num_frames();
    KeptSample k;
    k.sample = path;
    k.keep_contacts = keep_contacts;
    k.blend = static_cast<int>(p.integer("redraw_blend"));
    if (k.blend < 0) throw Error("redraw_blend must be >= 0 frames");
    k.redraw = {0, n - 1};
    if (!range.empty()) {
      std::vector<std::int64_t> r = range;
      if (r.size() == 2 && r[1] == -1) r[1] = n - 1;  // -1: the last frame
      if (r.size() != 2 || r[0] < 0 || r[1] < r[0] || r[1] >= n)
        throw Error(fmt::format("redraw must be [first, last] with 0 <= first <= last < {} (the sample's frames), got [{}]",
                                n, fmt::join(range, ", ")));
      k.redraw = {r[0], r[1]};
    }
    hands_.keep = k;
  }

  Trajectory trajectory_;
  TrajectoryObject object_;
  HandConstraints hands_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::FileTrajectory)
