#include "core/trajectory/keyframes.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/geometry/rotation.h"
#include "core/trajectory/cubic_spline.h"
#include "core/trajectory/rotation_spline.h"
#include "core/trajectory/validation.h"

namespace bimart {

std::int64_t keyframe_count(double first_time, double last_time, double fps) {
  const double frames = (last_time - first_time) * fps;
  if (!(frames < 1e15)) return std::numeric_limits<std::int64_t>::max();  // also NaN
  return static_cast<std::int64_t>(std::floor(frames + 1e-6)) + 1;
}

void sample_keyframes(const std::vector<Keyframe>& keys, double fps, bool rest, const std::string& file,
                      Trajectory& out) {
  if (keys.size() < 2)
    throw Error(SourceLocation{file, keys.empty() ? 0 : keys[0].line, 0},
                fmt::format("a keyframe trajectory needs at least 2 keys, got {}", keys.size()));
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const Keyframe& k = keys[i];
    const SourceLocation at{file, k.line, 0};
    if (!std::isfinite(k.t)) throw Error(at, "t is not a finite number");
    if (i > 0 && !(k.t > keys[i - 1].t))
      throw Error(at, fmt::format("key times must strictly increase: t = {} s comes after t = {} s (line {})", k.t,
                                  keys[i - 1].t, keys[i - 1].line));
    if ((k.position && !k.position->allFinite()) || (k.angle && !std::isfinite(*k.angle)) ||
        (k.rotation && !k.rotation->coeffs().allFinite()))
      throw Error(at, "a value of this key is not a finite number");
  }
  if (!(fps > 0 && std::isfinite(fps))) throw Error(SourceLocation{file, 0, 0}, fmt::format("fps must be positive, got {}", fps));
  const double t0 = keys.front().t, t1 = keys.back().t;
  const std::int64_t n = keyframe_count(t0, t1, fps);
  check_frame_count(n, SourceLocation{file, keys.back().line, 0},
                    fmt::format("keys from t = {} s to t = {} s at {} fps", t0, t1, fps));

  const CubicSpline::End end = rest ? CubicSpline::End::Clamped : CubicSpline::End::Natural;
  // One spline per scalar channel over the keys that give it.
  std::vector<double> tp, ta, tr;
  std::vector<std::vector<double>> pos(3);
  std::vector<double> ang;
  std::vector<Eigen::Quaterniond> rot;
  std::vector<int> angle_lines;
  out.angle_keys.clear();
  for (const Keyframe& k : keys) {
    if (k.position) {
      tp.push_back(k.t);
      for (int c = 0; c < 3; ++c) pos[c].push_back((*k.position)[c]);
    }
    if (k.angle) {
      ta.push_back(k.t);
      ang.push_back(*k.angle);
      angle_lines.push_back(k.line);
      out.angle_keys.emplace_back(*k.angle, k.line);
    }
    if (k.rotation) {
      tr.push_back(k.t);
      rot.push_back(k.rotation->normalized());
    }
  }
  std::vector<CubicSpline> position;
  if (!tp.empty())
    for (int c = 0; c < 3; ++c) position.emplace_back(tp, pos[c], end);
  std::optional<CubicSpline> angle;
  if (!ta.empty()) angle.emplace(ta, ang, end);
  std::optional<RotationSpline> rotation;
  if (!tr.empty()) rotation.emplace(tr, rot, end);

  // Lines shown for a frame: the hinge keys around it (or any keys when none gives the angle).
  std::vector<double> line_times = ta;
  std::vector<int> lines = angle_lines;
  if (line_times.empty())
    for (const Keyframe& k : keys) {
      line_times.push_back(k.t);
      lines.push_back(k.line);
    }

  out.states.setZero(n, 7);
  out.lines.assign(n, {0, 0});
  out.fps = fps;
  out.start_time = t0;
  out.from_keyframes = true;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (std::int64_t f = 0; f < n; ++f) {
    const double t = std::min(t0 + static_cast<double>(f) / fps, t1);
    if (angle) out.states(f, 0) = (*angle)(t);
    if (rotation) {
      previous = unwrap_axis_angle(matrix_to_axis_angle((*rotation)(t).toRotationMatrix()), previous);
      out.states.block<1, 3>(f, 1) = previous.transpose();
    }
    for (std::size_t c = 0; c < position.size(); ++c) out.states(f, 4 + c) = position[c](t);
    const std::size_t i = std::upper_bound(line_times.begin(), line_times.end(), t) - line_times.begin();
    out.lines[f] = {lines[i == 0 ? 0 : i - 1], i < lines.size() && i > 0 ? lines[i] : 0};
  }
}

}  // namespace bimart
