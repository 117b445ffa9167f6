#include "core/export/viewer_marks.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "core/directing/refine_directions.h"

namespace bimart {
namespace {

const char* const kHands[2] = {"left", "right"};

std::string frames_text(std::int64_t first, std::int64_t last) {
  return first == last ? fmt::format("frame {}", first) : fmt::format("frames {}-{}", first, last);
}

// Squared distance from p to the nearest vertex of `mesh` (a one-off query over a few
// thousand vertices: a k-d tree would cost more to build than this scan).
double nearest_vertex_sq(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v)
    best = std::min(best, (mesh.vertices.row(v).transpose() - p).squaredNorm());
  return best;
}

}  // namespace

std::vector<ViewerMark> viewer_marks(const HandConstraints& constraints, const SceneSource& source) {
  const std::int64_t last_frame = source.sequence.num_frames() - 1;
  std::vector<ViewerMark> marks;
  const auto clipped = [&](const FrameRange& r, ViewerMark& m) {
    m.first = std::min(r.first, last_frame);
    m.last = std::min(r.last, last_frame);
  };
  for (const ContactConstraint& c : constraints.contacts) {
    ViewerMark m;
    m.hand = c.hand;
    clipped(c.frames, m);
    m.kind = contact_part_name(c.part);
    m.label = c.part == ContactPart::None
                  ? fmt::format("{}: off the object (≥ {:g} cm), {}", kHands[c.hand], 100 * c.clearance,
                                frames_text(m.first, m.last))
                  : fmt::format("{}: on the {}{}, {}", kHands[c.hand],
                                c.part == ContactPart::Any ? std::string("object") : std::string(m.kind) + " part",
                                c.region ? fmt::format(" within {:g} cm of a point", 100 * c.region->radius) : "",
                                frames_text(m.first, m.last));
    if (c.region) {
      const Eigen::Vector3d& p = c.region->point;
      m.region_point = std::array<double, 3>{p.x(), p.y(), p.z()};
      m.region_radius = c.region->radius;
      const bool on_top = c.part == ContactPart::Top ||
                          (c.part == ContactPart::Any &&
                           nearest_vertex_sq(source.object.top, p) <= nearest_vertex_sq(source.object.bottom, p));
      m.region_part = on_top ? "top" : "bottom";
    }
    marks.push_back(std::move(m));
  }
  if (!constraints.pins.empty()) {
    // The wrists as the refinement pins them: pose pins carried with the object to their frames.
    std::vector<HandPin> pins = constraints.pins;
    const RefineDirections r = pinned_targets(pins, source.models(), source.sequence.object_states);
    for (const HandPin& pin : pins) {
      ViewerMark m;
      m.hand = pin.hand;
      clipped(pin.frames, m);
      m.kind = pin.whole_pose() ? "pose" : "wrist";
      m.label = pin.whole_pose()
                    ? fmt::format("{}: pose of {} frame {}, {}", kHands[pin.hand], pin.source, pin.source_frame,
                                  frames_text(m.first, m.last))
                    : fmt::format("{}: wrist pinned{}, {}", kHands[pin.hand], pin.rotation ? " and turned" : "",
                                  frames_text(m.first, m.last));
      for (const auto& p : r.pins[static_cast<std::size_t>(pin.hand)])
        if (p.frame >= m.first && p.frame <= m.last) m.wrists.push_back({p.wrist.x(), p.wrist.y(), p.wrist.z()});
      marks.push_back(std::move(m));
    }
  }
  if (constraints.keep) {
    const KeptSample& k = *constraints.keep;
    ViewerMark m;
    m.hand = -1;
    clipped(k.redraw, m);
    m.kind = "redraw";
    m.label = fmt::format("drawn anew: {} (the rest as in {})", frames_text(m.first, m.last), k.sample);
    marks.push_back(m);
    if (k.keep_contacts) {
      m.first = 0;
      m.last = last_frame;
      m.kind = "contacts";
      m.label = "contact maps kept from " + k.sample;
      marks.push_back(m);
    }
  }
  return marks;
}

}  // namespace bimart
