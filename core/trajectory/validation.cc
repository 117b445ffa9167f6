#include "core/trajectory/validation.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>

namespace bimart {

namespace {

double deg(double rad) { return rad * 180.0 / M_PI; }

std::string limits_text(const ArticulatedObject& o) {
  return fmt::format("the limits [{:.4g}, {:.4g}] deg of object '{}'", deg(o.angle_min), deg(o.angle_max), o.name);
}

}  // namespace

void check_frame_count(std::int64_t n, const SourceLocation& where, const std::string& what) {
  if (n < 2)
    throw Error(where, fmt::format("a trajectory needs at least 2 frames; {} give {}", what, n));
  if (n > kMaxTrajectoryFrames)
    throw Error(where, fmt::format("a trajectory may have at most {} frames ({} min at 30 fps); {} give {}",
                                   kMaxTrajectoryFrames, kMaxTrajectoryFrames / 1800, what,
                                   n == std::numeric_limits<std::int64_t>::max() ? "far more" : std::to_string(n)));
}

void validate_trajectory(const Trajectory& tr, const ArticulatedObject& object) {
  const SourceLocation file{tr.file, 0, 0};
  check_frame_count(tr.num_frames(), file, fmt::format("{} frames", tr.num_frames()));
  if (!(tr.fps > 0 && std::isfinite(tr.fps))) throw Error(file, fmt::format("fps must be positive, got {}", tr.fps));
  static const char* const fields[7] = {"angle", "rx", "ry", "rz", "tx", "ty", "tz"};
  for (std::int64_t f = 0; f < tr.num_frames(); ++f)
    for (int c = 0; c < 7; ++c)
      if (!std::isfinite(tr.states(f, c)))
        throw Error(tr.frame_location(f), tr.describe_frame(f) + ": " + fields[c] + " is not a finite number");
  const double lo = object.angle_min - kHingeLimitTolerance, hi = object.angle_max + kHingeLimitTolerance;
  for (const auto& [angle, line] : tr.angle_keys)
    if (angle < lo || angle > hi)
      throw Error(SourceLocation{tr.file, line, 0},
                  fmt::format("the hinge angle {:.4g} deg of this key is outside {}", deg(angle), limits_text(object)));
  for (std::int64_t f = 0; f < tr.num_frames(); ++f) {
    const double a = tr.states(f, 0);
    if (a < lo || a > hi)
      throw Error(tr.frame_location(f),
                  fmt::format("{}: the hinge angle {:.4g} deg is outside {}{}", tr.describe_frame(f), deg(a),
                              limits_text(object),
                              tr.from_keyframes ? " (the spline between keys overshoots: move the keys away from "
                                                  "the limit or add keys)"
                                                : ""));
  }
}

}  // namespace bimart
