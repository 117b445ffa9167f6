#include "core/directing/hand_constraints.h"

#include <ATen/ATen.h>
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/io/sequence.h"
#include "core/object/canonical_frame.h"
#include "core/object/object_io.h"
#include "core/object/object_state.h"
#include "core/trajectory/yaml_reader.h"
#include "core/util/log.h"
#include "core/util/yaml_keys.h"

namespace bimart {

const char* contact_part_name(ContactPart p) {
  switch (p) {
    case ContactPart::Top: return "top";
    case ContactPart::Bottom: return "bottom";
    case ContactPart::Any: return "any";
    case ContactPart::None: return "none";
  }
  return "?";
}

double ContactConstraint::clearance_at(std::int64_t frame) const {
  if (part != ContactPart::None) return 0;
  const std::int64_t outside = std::max(frames.first - frame, frame - frames.last);  // > 0 on a ramp
  if (outside <= 0) return clearance;
  const int cut = frame < frames.first ? ramp_before : ramp_after;
  const int side = cut < 0 ? ramp : cut;
  if (outside > side) return 0;
  return clearance * 0.5 * (1 + std::cos(M_PI * static_cast<double>(outside) / (side + 1)));
}

FrameRange ContactConstraint::with_ramps(std::int64_t n) const {
  return {std::max<std::int64_t>(0, frames.first - ramp), std::min(frames.last + ramp, n - 1)};
}

namespace {

const char* const kHandNames[2] = {"left", "right"};

std::string frames_text(const FrameRange& r) {
  return r.first == r.last ? fmt::format("frame {}", r.first) : fmt::format("frames {}-{}", r.first, r.last);
}

struct Parser : YamlReader {
  const Trajectory* tr = nullptr;
  std::string base_folder;

  std::int64_t last_frame() const { return tr->num_frames() - 1; }

  std::int64_t frame_number(const YAML::Node& n, const std::string& field) const {
    return whole(n, field, 0, last_frame());
  }

  // Seconds on the trajectory's clock (a keyframe file's `t`) to the nearest frame.
  std::int64_t frame_at(const YAML::Node& n) const {
    const double t = number(n, "t");
    const double f = std::round((t - tr->start_time) * tr->fps);
    if (f < 0 || f > static_cast<double>(last_frame()))
      throw Error(at(n), fmt::format("t = {} s is outside the trajectory ({} s to {} s)", t, tr->start_time,
                                     tr->start_time + static_cast<double>(last_frame()) / tr->fps));
    return static_cast<std::int64_t>(f);
  }

  // `frames: [a, b]` (inclusive) or `frames: all`, `frame: n`, `t: s` or `t: [s0, s1]`; none: every frame.
  FrameRange frames(const YAML::Node& e) const {
    const int given = (e["frames"] ? 1 : 0) + (e["frame"] ? 1 : 0) + (e["t"] ? 1 : 0);
    if (given > 1) throw Error(at(e), "give one of frames, frame and t");
    FrameRange r{0, last_frame()};
    if (const YAML::Node n = e["frames"]) {
      if (n.IsScalar() && n.Scalar() == "all") return r;
      if (!n.IsSequence() || n.size() != 2)
        throw Error(at(n), "frames must be [first, last] (both included) or all");
      r = {frame_number(n[0], "frames"), frame_number(n[1], "frames")};
    } else if (const YAML::Node n = e["frame"]) {
      r.first = r.last = frame_number(n, "frame");
    } else if (const YAML::Node n = e["t"]) {
      if (n.IsSequence()) {
        if (n.size() != 2) throw Error(at(n), "t must be a time or [from, to] in seconds");
        r = {frame_at(n[0]), frame_at(n[1])};
      } else {
        r.first = r.last = frame_at(n);
      }
    }
    if (r.first > r.last) throw Error(at(e), fmt::format("the range ends ({}) before it starts ({})", r.last, r.first));
    return r;
  }

  ContactPart part(const YAML::Node& n) const {
    const std::string s = text(n, "part");
    if (s == "top") return ContactPart::Top;
    if (s == "bottom") return ContactPart::Bottom;
    if (s == "any") return ContactPart::Any;
    if (s == "none") return ContactPart::None;
    throw Error(at(n), "part must be top, bottom, any or none, got '" + s + "'");
  }

  void entry(const YAML::Node& e, int hand, HandConstraints& out) const {
    if (!e.IsMap()) throw Error(at(e), "each entry of a hand must be a map (frames, part, wrist, ...)");
    check_known_keys(e, {"frames", "frame", "t", "part", "region", "clearance", "ramp", "wrist", "rotation", "pose"}, file,
                     "a hand constraint");
    const FrameRange range = frames(e);
    if (!e["part"] && !e["wrist"] && !e["pose"])
      throw Error(at(e), "this entry asks nothing: give part (top, bottom, any, none), wrist or pose");
    if (const YAML::Node p = e["part"]) {
      ContactConstraint c;
      c.hand = hand;
      c.frames = range;
      c.part = part(p);
      c.where = at(e);
      if (const YAML::Node r = e["region"]) {
        if (c.part == ContactPart::None) throw Error(at(r), "a region goes with part top, bottom or any, not none");
        check_known_keys(r, {"point", "radius"}, file, "region");
        if (!r.IsMap() || !r["point"] || !r["radius"])
          throw Error(at(r), "region must be {point: [x, y, z], radius: r} (object frame, metres)");
        c.region = ContactRegion{vec3(r["point"], "region.point"), number(r["radius"], "region.radius")};
        if (!(c.region->radius > 0)) throw Error(at(r["radius"]), "region.radius must be > 0 (metres)");
      }
      if (const YAML::Node n = e["clearance"]) {
        if (c.part != ContactPart::None) throw Error(at(n), "clearance goes with part: none");
        c.clearance = number(n, "clearance");
        if (!(c.clearance > 0 && c.clearance <= 0.5)) throw Error(at(n), "clearance must be in (0, 0.5] metres");
      }
      if (const YAML::Node n = e["ramp"]) {
        if (c.part != ContactPart::None) throw Error(at(n), "ramp goes with part: none");
        c.ramp = static_cast<int>(whole(n, "ramp (frames)", 0, 120));
      }
      out.contacts.push_back(c);
    } else {
      for (const char* k : {"region", "clearance", "ramp"})
        if (e[k]) throw Error(at(e[k]), std::string(k) + " goes with part");
    }
    if (!e["wrist"] && !e["pose"]) {
      if (e["rotation"]) throw Error(at(e["rotation"]), "rotation goes with wrist (the wrist's position)");
      return;
    }
    HandPin pin;
    pin.hand = hand;
    pin.frames = range;
    pin.where = at(e);
    if (const YAML::Node w = e["wrist"]) {
      if (e["pose"]) throw Error(at(e["pose"]), "give either wrist (and rotation) or pose, not both");
      pin.wrist = vec3(w, "wrist");
      if (const YAML::Node r = e["rotation"]) pin.rotation = rotation(r);
    } else {
      const YAML::Node p = e["pose"];
      if (e["rotation"]) throw Error(at(e["rotation"]), "rotation goes with wrist; pose gives the whole hand");
      check_known_keys(p, {"sample", "frame"}, file, "pose");
      if (!p.IsMap() || !p["sample"] || !p["frame"])
        throw Error(at(p), "pose must be {sample: SEQUENCE.npz, frame: N}: that hand's pose relative to the object there");
      std::filesystem::path s = text(p["sample"], "pose.sample");
      if (s.is_relative() && !base_folder.empty()) s = std::filesystem::path(base_folder) / s;
      pin.source = s.lexically_normal().string();
      if (!std::filesystem::is_regular_file(pin.source))
        throw Error(at(p["sample"]), "pose.sample: no sequence file " + pin.source);
      const std::int64_t n = read_sequence(pin.source).num_frames();
      pin.source_frame = whole(p["frame"], "pose.frame (of " + pin.source + ")", 0, n - 1);
    }
    out.pins.push_back(pin);
  }
};

// The ramps of `none` constraints cut to the frames between them and the hand's other
// contact constraints: a hand asked to touch until frame 60 is not pushed off before it.
void fit_ramps(std::vector<ContactConstraint>& contacts) {
  for (ContactConstraint& c : contacts) {
    if (c.part != ContactPart::None) continue;
    c.ramp_before = c.ramp_after = c.ramp;
    for (const ContactConstraint& o : contacts) {
      if (&o == &c || o.hand != c.hand) continue;
      if (o.frames.last < c.frames.first)
        c.ramp_before = static_cast<int>(std::min<std::int64_t>(c.ramp_before, c.frames.first - o.frames.last - 1));
      if (o.frames.first > c.frames.last)
        c.ramp_after = static_cast<int>(std::min<std::int64_t>(c.ramp_after, o.frames.first - c.frames.last - 1));
    }
  }
}

template <class T>
void check_overlaps(const std::vector<T>& list, const char* what) {
  for (std::size_t i = 0; i < list.size(); ++i)
    for (std::size_t j = 0; j < i; ++j) {
      const T &a = list[j], &b = list[i];
      if (a.hand != b.hand || a.frames.last < b.frames.first || b.frames.last < a.frames.first) continue;
      throw Error(b.where, fmt::format("the {} hand already has {} over {} (at {}): ranges of one hand must not overlap",
                                       kHandNames[b.hand], what, frames_text(a.frames), a.where.str()));
    }
}

HandConstraints parse_node(const YAML::Node& hands, const Parser& p) {
  HandConstraints out;
  if (!hands || hands.IsNull()) return out;
  if (!hands.IsMap()) throw Error(p.at(hands), "hands must be a map: left, right or both, each a list of entries");
  check_known_keys(hands, {"left", "right", "both"}, p.file, "hands");
  for (const auto& kv : hands) {
    const std::string side = kv.first.Scalar();
    const YAML::Node list = kv.second;
    if (!list.IsSequence()) throw Error(p.at(list), "hands." + side + " must be a list of entries (- frames: ..., part: ...)");
    for (const YAML::Node& e : list) {
      if (side != "right") p.entry(e, 0, out);
      if (side != "left") p.entry(e, 1, out);
    }
  }
  check_overlaps(out.contacts, "a contact constraint");
  check_overlaps(out.pins, "a pin");
  fit_ramps(out.contacts);
  return out;
}

YAML::Node load_text(const std::string& text, const std::string& label) {
  try {
    check_duplicate_keys(text, label);
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw Error(SourceLocation{label, e.mark.line + 1, e.mark.column + 1}, e.msg);
  }
}

}  // namespace

std::vector<double> KeptSample::weights(std::int64_t n) const {
  std::vector<double> w(static_cast<std::size_t>(n), 1.0);
  const std::int64_t a = redraw.first, b = std::min(redraw.last, n - 1);
  const std::int64_t len = b - a + 1;
  const std::int64_t ramp = std::min<std::int64_t>(blend, len / 2);
  for (std::int64_t f = a; f <= b; ++f) {
    const std::int64_t in = std::min(f - a, b - f);  // frames from the nearer end of the stretch
    // Kept frames before and after: a ramp of `ramp` frames down from 1 (the stretch's ends
    // that touch the sequence's ends have nothing to join).
    const bool joins = (f - a <= b - f) ? a > 0 : b < n - 1;
    w[static_cast<std::size_t>(f)] =
        joins && in < ramp ? 0.5 + 0.5 * std::cos(M_PI * (static_cast<double>(in) + 1.0) / (static_cast<double>(ramp) + 1.0)) : 0.0;
  }
  return w;
}

std::string HandConstraints::describe() const {
  std::string s;
  const auto add = [&](const std::string& t) { s += (s.empty() ? "" : "; ") + t; };
  for (const auto& c : contacts)
    add(fmt::format("{}: {}{} over {}", kHandNames[c.hand], contact_part_name(c.part), c.region ? " (region)" : "",
                    frames_text(c.frames)));
  for (const auto& p : pins)
    add(fmt::format("{}: {} at {}", kHandNames[p.hand],
                    p.whole_pose() ? "pose of " + p.source : (p.rotation ? "pinned wrist and rotation" : "pinned wrist"),
                    frames_text(p.frames)));
  if (keep)
    add(fmt::format("{} kept outside {}{}", keep->sample, frames_text(keep->redraw),
                    keep->keep_contacts ? " (its contact maps everywhere)" : ""));
  return s.empty() ? "none" : s;
}

HandConstraints read_hand_constraints(const std::string& path, const Trajectory& trajectory, bool required) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext != ".yaml" && ext != ".yml") {
    if (required) throw Error(path + ": hand constraints are read from a .yaml file with a `hands:` block");
    return {};
  }
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  const YAML::Node root = load_text(ss.str(), path);
  if (required && (!root.IsMap() || !root["hands"])) throw Error(path + ": no `hands:` block (docs/directing.md)");
  if (!root.IsMap()) return {};
  Parser p;
  p.file = path;
  p.tr = &trajectory;
  p.base_folder = std::filesystem::path(path).parent_path().string();
  return parse_node(root["hands"], p);
}

HandConstraints parse_hand_constraints(const std::string& text, const std::string& label,
                                       const std::string& base_folder, const Trajectory& trajectory) {
  Parser p;
  p.file = label;
  p.tr = &trajectory;
  p.base_folder = base_folder;
  return parse_node(load_text(text, label), p);
}

std::pair<at::Tensor, at::Tensor> hands_that_may_hold(const HandConstraints& constraints, std::int64_t N) {
  at::Tensor any = at::ones({N, 2}, at::kBool), top = at::ones({N, 2}, at::kBool);
  for (const ContactConstraint& c : constraints.contacts) {
    if (c.frames.last >= N)
      throw Error(c.where, fmt::format("frames up to {}, but the trajectory has {} frames", c.frames.last, N));
    const auto span = [&](at::Tensor& m) { return m.slice(0, c.frames.first, c.frames.last + 1).select(1, c.hand); };
    if (c.part == ContactPart::None) span(any).fill_(false);
    if (c.part == ContactPart::None || c.part == ContactPart::Bottom) span(top).fill_(false);
  }
  return {any, top};
}

Eigen::Isometry3d object_pose_at(const at::Tensor& states, std::int64_t frame) {
  const at::Tensor row = states[frame].to(at::kDouble).contiguous();
  return canonical_to_world(ObjectState::from_row(row.data_ptr<double>()));
}

HandConstraints read_hand_constraints_for_sample(const std::string& file, const std::string& sample_path, double fps) {
  Trajectory clock;
  try {
    clock = read_trajectory(file, fps);
  } catch (const Error&) {
    clock = read_trajectory(sample_path);
  }
  return read_hand_constraints(file, clock, true);
}

PinnedPose read_pinned_pose(const HandPin& pin) {
  const Sequence seq = read_sequence(pin.source);
  const HandParams& p = seq.hands.hands[static_cast<std::size_t>(pin.hand)];
  const std::int64_t f = pin.source_frame;
  const auto vec = [](const at::Tensor& t) {
    const at::Tensor d = t.to(at::kDouble).contiguous();
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(d.data_ptr<double>(), d.numel()));
  };
  // The source's object pose for the object in its canonical pose, as the pipeline poses it
  // (core/object/canonical_frame.h). A sample the pipeline wrote names its canonical copy
  // already; when the object cannot be read, its pose is taken as it is.
  Eigen::Isometry3d from_source = Eigen::Isometry3d::Identity();
  try {
    from_source = to_canonical(load_object(resolve_object_path(seq, pin.source))).from_source;
  } catch (const Error& e) {
    log::warn("pose pin: {}: the object's canonical pose is unknown ({}); its pose is taken as stored", pin.source,
              e.what());
  }
  return {Eigen::Vector3d(vec(p.rot[f])), Eigen::Vector3d(vec(p.trans[f])), vec(p.pose[f]), vec(p.shape),
          object_pose_at(seq.object_states, f) * from_source.inverse()};
}

void merge_hand_constraints(HandConstraints& base, const HandConstraints& extra) {
  base.contacts.insert(base.contacts.end(), extra.contacts.begin(), extra.contacts.end());
  base.pins.insert(base.pins.end(), extra.pins.begin(), extra.pins.end());
  check_overlaps(base.contacts, "a contact constraint");
  check_overlaps(base.pins, "a pin");
  fit_ramps(base.contacts);
}

}  // namespace bimart
