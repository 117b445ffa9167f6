// Directing the hands (docs/directing.md): what an animator asks of a hand over chosen
// frames — which part it holds (or that it stays off the object), where on it, and where
// its wrist (or its whole pose) is at a frame. Written as a `hands:` block in a trajectory
// file or given to `trajectory.file`'s `hands` parameter:
//
//   hands:
//     right:
//       - frames: [0, 75]            # inclusive frame numbers; or frame: 40; or t: [0.5, 1.2] (s)
//         part: top                  # top | bottom | any | none
//         region: {point: [0.1, 0.02, 0.0], radius: 0.04}   # optional: object frame, m
//     left:
//       - frames: [30, 60]
//         part: none                 # stays `clearance` (default 3 cm) off the object
//       - frame: 40
//         wrist: [0.05, 0.25, 0.12]  # world frame, m
//         rotation: {euler_xyz: [0, 90, 0]}   # optional: the wrist's orientation, degrees
//       - frame: 50
//         pose: {sample: out/bimart/sample_0.npz, frame: 12}   # that hand's grasp there
//
// The constraints act on sampling (core/directing/contact_rules.h, hand_pins.h) and on the
// refinement; this file holds only what was asked, checked against the trajectory.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <ATen/core/Tensor.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/trajectory/trajectory.h"
#include "core/util/error.h"

namespace bimart {

enum class ContactPart { Top, Bottom, Any, None };
const char* contact_part_name(ContactPart p);

// Frames first..last, both included.
struct FrameRange {
  std::int64_t first = 0, last = 0;
  bool contains(std::int64_t f) const { return f >= first && f <= last; }
};

// A spot on the object: a point in the object's canonical frame with the hinge at angle 0
// (where `bimart object` shows it; a point on the top part moves with it) and a radius.
struct ContactRegion {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double radius = 0;
};

struct ContactConstraint {
  int hand = 0;  // 0 = left, 1 = right
  FrameRange frames;
  ContactPart part = ContactPart::Any;  // top/bottom/any: the hand touches that; none: it stays off
  std::optional<ContactRegion> region;  // with top/bottom/any: the hand touches inside it
  double clearance = 0.03;              // none: metres between the hand and the object
  SourceLocation where;
  // none: over this many frames before the range the clearance fades in and after it fades
  // out (raised cosine), so the hand lets go and comes back smoothly. Each side is cut to
  // the frames left free by the hand's other contact constraints (ramp_before, ramp_after;
  // -1 = ramp), as the readers set them.
  int ramp = 8;
  int ramp_before = -1, ramp_after = -1;
  // none: the clearance the hand keeps at `frame` (the full one inside the range, fading on
  // the ramps, 0 elsewhere); 0 for other parts.
  double clearance_at(std::int64_t frame) const;
  // The frames the range and its ramps cover, cut to [0, frames).
  FrameRange with_ramps(std::int64_t frames) const;
};

// A hand held at chosen frames: its wrist (MANO's root joint) at `wrist` (world frame, m),
// optionally turned to `rotation` (world frame, MANO's global orientation); or its whole
// pose relative to the object as at frame `source_frame` of the sequence `source`.
struct HandPin {
  int hand = 0;
  FrameRange frames;
  std::optional<Eigen::Vector3d> wrist;
  std::optional<Eigen::Quaterniond> rotation;
  std::string source;  // sequence file (absolute or relative to the working folder), "" = none
  std::int64_t source_frame = 0;
  SourceLocation where;
  bool whole_pose() const { return !source.empty(); }
};

// An earlier sample redrawn over a stretch (`bimart edit`): outside `redraw` its contact
// maps and hands are kept exactly, inside they are sampled anew, and over the first and
// last `blend` frames of the stretch the kept values fade out and in (the raised-cosine
// ramps of the window fusion, core/diffusion/generation.cc). keep_contacts: its contact
// maps are kept over every frame too, only the motion is redrawn.
struct KeptSample {
  std::string sample;  // sequence file
  FrameRange redraw;
  bool keep_contacts = false;
  int blend = 8;
  // Per frame (N): how much of the sample is kept, 1 outside the stretch, 0 well inside.
  std::vector<double> weights(std::int64_t frames) const;
};

struct HandConstraints {
  std::vector<ContactConstraint> contacts;
  std::vector<HandPin> pins;
  std::optional<KeptSample> keep;
  bool empty() const { return contacts.empty() && pins.empty() && !keep; }
  // "right: top over frames 0-75; left: pinned wrist at frame 40" for logs.
  std::string describe() const;
};

// The `hands:` block of the YAML file `path` (none: empty), for `trajectory` (its frame
// count, fps and start time turn `t:` into frames). Errors name the file and line, with
// "did you mean" for unknown keys; frames outside the trajectory, two contact constraints
// of one hand on the same frame and a pin without wrist or pose are errors. `required`: a
// file without the block is an error too (a file given only for its constraints).
HandConstraints read_hand_constraints(const std::string& path, const Trajectory& trajectory, bool required = false);

// The same for a sample made earlier (`bimart view --hands`, `bimart constraints`): the block
// of `file` (the trajectory file the sample was made with, or a file with only the block),
// `t:` on the file's clock when it is a trajectory, else on the sample's (`sample_path`).
// `fps`: the sample's frame rate.
HandConstraints read_hand_constraints_for_sample(const std::string& file, const std::string& sample_path, double fps);

// The same from YAML text (a `hands:` block's value, e.g. `{right: [{part: top}]}`), `label`
// naming it in messages; relative sample paths are relative to `base_folder`.
HandConstraints parse_hand_constraints(const std::string& text, const std::string& label,
                                       const std::string& base_folder, const Trajectory& trajectory);

// Per frame and hand [N, 2] bool: may the hand hold the object there (no `none`), and may it
// be on the top part (no `none` or `bottom`): what the hold terms of the guidance and the
// refinement may choose from.
std::pair<at::Tensor, at::Tensor> hands_that_may_hold(const HandConstraints& constraints, std::int64_t frames);

// A pose pin's source: the hand's MANO parameters at its frame (world frame) and the
// object's pose there. Throws naming the file when it cannot be read.
struct PinnedPose {
  Eigen::Vector3d rot, trans;  // axis-angle, metres
  Eigen::VectorXd pose, shape;  // [45], [10]
  Eigen::Isometry3d object;    // canonical -> world at the source frame
};
PinnedPose read_pinned_pose(const HandPin& pin);

// The object's pose (canonical -> world) at frame `frame` of states [N, 7].
Eigen::Isometry3d object_pose_at(const at::Tensor& states, std::int64_t frame);

// Every constraint of `extra` added to `base`, checked again for overlaps.
void merge_hand_constraints(HandConstraints& base, const HandConstraints& extra);

}  // namespace bimart
