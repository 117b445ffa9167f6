#include "core/directing/constraint_report.h"

#include <ATen/ATen.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/directing/refine_directions.h"
#include "core/geometry/rotation.h"
#include "core/hand/lbs.h"
#include "core/io/sequence.h"
#include "core/metrics/contact.h"
#include "core/object/object_distance.h"
#include "core/object/object_state.h"

namespace bimart {
namespace {

const char* const kHands[2] = {"left", "right"};

std::string frames_text(const FrameRange& r) {
  return r.first == r.last ? fmt::format("frame {}", r.first) : fmt::format("frames {}-{}", r.first, r.last);
}

Eigen::VectorXd row(const at::Tensor& t) {
  const at::Tensor d = t.to(at::kDouble).contiguous();
  return Eigen::Map<const Eigen::VectorXd>(d.data_ptr<double>(), d.numel());
}

// The posed hand and the object at each frame, computed once per frame asked for.
class Posed {
 public:
  explicit Posed(const SceneSource& s) : s_(s), distance_(s.object) {}

  ObjectState state(std::int64_t t) const {
    const at::Tensor r = s_.sequence.object_states[t].to(at::kDouble).contiguous();
    return ObjectState::from_row(r.data_ptr<double>());
  }
  LbsResult<double> hand(int h, std::int64_t t) const {
    const HandParams& p = s_.sequence.hands.hands[static_cast<std::size_t>(h)];
    return lbs<double>(*s_.models()[static_cast<std::size_t>(h)], Eigen::Vector3d(row(p.rot[t])), row(p.pose[t]),
                       Eigen::Vector3d(row(p.trans[t])), row(p.shape));
  }
  // The hand's vertices' surface queries against the whole object at frame t.
  std::vector<ObjectSurfaceQuery> queries(int h, std::int64_t t) const {
    const LbsResult<double> r = hand(h, t);
    const ObjectState st = state(t);
    std::vector<ObjectSurfaceQuery> q;
    q.reserve(static_cast<std::size_t>(r.vertices.rows()));
    for (Eigen::Index v = 0; v < r.vertices.rows(); ++v) q.push_back(distance_.query(st, r.vertices.row(v).transpose()));
    return q;
  }
  // A world point on `part` at frame t back in the object's frame with the hinge at 0.
  Eigen::Vector3d rest(const Eigen::Vector3d& world, ObjectPart part, std::int64_t t) const {
    const ObjectState st = state(t);
    const Eigen::Vector3d canonical = canonical_to_world(st).inverse() * world;
    return part == ObjectPart::Top ? Eigen::Vector3d(top_to_canonical(st.angle).inverse() * canonical) : canonical;
  }

 private:
  const SceneSource& s_;
  ObjectDistance distance_;
};

ConstraintCheck check_contact(const ContactConstraint& c, const Posed& posed, std::int64_t last_frame) {
  ConstraintCheck out;
  const FrameRange r{c.frames.first, std::min(c.frames.last, last_frame)};
  const std::int64_t n = r.last - r.first + 1;
  if (c.part == ContactPart::None) {
    double nearest = std::numeric_limits<double>::infinity();
    std::int64_t under = 0, at = r.first;
    for (std::int64_t t = r.first; t <= r.last; ++t) {
      double frame_nearest = std::numeric_limits<double>::infinity();
      for (const auto& q : posed.queries(c.hand, t)) frame_nearest = std::min(frame_nearest, -q.signed_distance);
      under += frame_nearest < c.clearance - 1e-3;
      if (frame_nearest < nearest) nearest = frame_nearest, at = t;
    }
    out.asked = fmt::format("{}: at least {:g} cm off the object, {}", kHands[c.hand], 100 * c.clearance, frames_text(r));
    out.measured = fmt::format("nearest {:.1f} mm (frame {}); {} of {} frames nearer than the clearance", 1000 * nearest,
                               at, under, n);
    out.value = nearest;
    out.holds = nearest >= c.clearance - 1e-3;
    return out;
  }
  std::int64_t on_part = 0, elsewhere = 0;
  for (std::int64_t t = r.first; t <= r.last; ++t) {
    bool hit = false, other = false;
    for (const auto& q : posed.queries(c.hand, t)) {
      if (q.signed_distance < -kContactDistance) continue;
      const bool part_ok = c.part == ContactPart::Any || (c.part == ContactPart::Top) == (q.part == ObjectPart::Top);
      const bool region_ok =
          !c.region || (posed.rest(q.closest, q.part, t) - c.region->point).norm() <= c.region->radius;
      (part_ok && region_ok ? hit : other) = true;
    }
    on_part += hit;
    elsewhere += other && !hit;
  }
  const std::string where = c.part == ContactPart::Any ? std::string("the object") : fmt::format("the {} part", contact_part_name(c.part));
  const std::string region = c.region ? fmt::format(" within {:g} cm of the region's point", 100 * c.region->radius) : "";
  out.asked = fmt::format("{}: on {}{}, {}", kHands[c.hand], where, region, frames_text(r));
  out.measured = fmt::format("touches it there in {} of {} frames ({:.1f} %); only elsewhere in {}", on_part, n,
                             100.0 * on_part / n, elsewhere);
  out.value = static_cast<double>(on_part) / n;
  out.holds = out.value >= 0.9;
  return out;
}

}  // namespace

std::vector<ConstraintCheck> check_constraints(const HandConstraints& constraints, const SceneSource& source) {
  const std::int64_t last_frame = source.sequence.num_frames() - 1;
  const Posed posed(source);
  std::vector<ConstraintCheck> out;
  for (const ContactConstraint& c : constraints.contacts)
    if (c.frames.first <= last_frame) out.push_back(check_contact(c, posed, last_frame));
  if (!constraints.pins.empty()) {
    std::vector<HandPin> pins = constraints.pins;
    const RefineDirections d = pinned_targets(pins, source.models(), source.sequence.object_states);
    for (const HandPin& pin : pins) {
      double wrist = 0, angle = 0, fingers = 0;
      for (const auto& p : d.pins[static_cast<std::size_t>(pin.hand)]) {
        if (!pin.frames.contains(p.frame)) continue;
        const LbsResult<double> r = posed.hand(pin.hand, p.frame);
        wrist = std::max(wrist, (r.joints.row(0).transpose() - p.wrist).norm());
        const HandParams& hp = source.sequence.hands.hands[static_cast<std::size_t>(pin.hand)];
        if (p.rotation) {
          const Eigen::Matrix3d R = axis_angle_to_matrix(Eigen::Vector3d(row(hp.rot[p.frame])));
          const double c = std::clamp(((p.rotation->transpose() * R).trace() - 1) / 2, -1.0, 1.0);
          angle = std::max(angle, std::acos(c) * 180 / M_PI);
        }
        if (p.fingers) fingers = std::max(fingers, (row(hp.pose[p.frame]) - *p.fingers).norm() / std::sqrt(45.0));
      }
      ConstraintCheck c;
      c.asked = fmt::format("{}: {} at {}", kHands[pin.hand],
                            pin.whole_pose() ? fmt::format("pose of {} frame {}", pin.source, pin.source_frame)
                                             : (pin.rotation ? "wrist and rotation pinned" : "wrist pinned"),
                            frames_text(pin.frames));
      c.measured = fmt::format("wrist {:.1f} mm from its pin", 1000 * wrist);
      if (pin.rotation || pin.whole_pose()) c.measured += fmt::format(", turned {:.1f} deg from it", angle);
      if (pin.whole_pose()) c.measured += fmt::format(", fingers {:.3f} rad (RMS) from the pose", fingers);
      c.value = wrist;
      c.holds = wrist <= 0.005 && angle <= 5.0;
      out.push_back(c);
    }
  }
  if (constraints.keep) {
    const KeptSample& k = *constraints.keep;
    const Sequence kept = read_sequence(k.sample);
    std::int64_t outside = 0, same = 0;
    for (std::int64_t t = 0; t <= std::min(last_frame, kept.num_frames() - 1); ++t) {
      if (k.redraw.contains(t)) continue;
      ++outside;
      bool equal = true;
      for (int h = 0; h < 2; ++h) {
        const HandParams &a = source.sequence.hands.hands[h], &b = kept.hands.hands[h];
        equal = equal && at::equal(a.rot[t], b.rot[t]) && at::equal(a.pose[t], b.pose[t]) && at::equal(a.trans[t], b.trans[t]);
      }
      same += equal;
    }
    ConstraintCheck c;
    c.asked = fmt::format("{} kept outside {}", k.sample, frames_text(k.redraw));
    c.measured = fmt::format("{} of {} frames outside the stretch bit-identical to it", same, outside);
    c.value = outside ? static_cast<double>(same) / outside : 1.0;
    c.holds = same == outside;
    out.push_back(c);
  }
  return out;
}

}  // namespace bimart
