#include "core/trajectory/trajectory.h"

#include <fmt/format.h>

#include <ATen/ATen.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "core/io/sequence.h"
#include "core/trajectory/csv_trajectory.h"
#include "core/trajectory/validation.h"
#include "core/trajectory/yaml_trajectory.h"

namespace bimart {

namespace {

// The object states and frame rate of a sequence file; its object path as stored.
Trajectory read_npz_trajectory(const std::string& path) {
  const Sequence s = read_sequence(path);
  Trajectory tr;
  tr.file = path;
  tr.fps = s.fps;
  const std::int64_t n = s.num_frames();
  check_frame_count(n, SourceLocation{path, 0, 0}, fmt::format("object_states of {} frames", n));
  const at::Tensor states = s.object_states.to(at::kDouble).contiguous();
  tr.states = Eigen::Map<const StateRows>(states.data_ptr<double>(), n, 7);
  tr.lines.assign(n, {0, 0});
  if (!s.object.empty()) {
    tr.object.path = s.object;
    tr.object.where = SourceLocation{path, 0, 0};
  }
  return tr;
}

}  // namespace

SourceLocation Trajectory::frame_location(std::int64_t frame) const {
  const int line = frame >= 0 && frame < static_cast<std::int64_t>(lines.size()) ? lines[frame][0] : 0;
  return {file, line, 0};
}

std::string Trajectory::describe_frame(std::int64_t frame) const {
  if (!from_keyframes) return fmt::format("frame {}", frame);
  const double t = start_time + static_cast<double>(frame) / fps;
  const auto l = frame >= 0 && frame < static_cast<std::int64_t>(lines.size()) ? lines[frame] : std::array<int, 2>{};
  if (l[1] > 0) return fmt::format("frame {} (t = {:.4g} s, between the keys at lines {} and {})", frame, t, l[0], l[1]);
  return fmt::format("frame {} (t = {:.4g} s, next to the key at line {})", frame, t, l[0]);
}

Trajectory read_trajectory(const std::string& path, double fps) {
  if (!(fps >= 0 && std::isfinite(fps))) throw Error(fmt::format("fps must be >= 0 (0: the file's), got {}", fps));
  if (!std::filesystem::is_regular_file(path)) throw Error(path + ": no such trajectory file");
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  Trajectory tr;
  if (ext == ".csv") {
    tr = read_csv_trajectory(path);
  } else if (ext == ".yaml" || ext == ".yml") {
    tr = read_yaml_trajectory(path, fps);
  } else if (ext == ".npz") {
    tr = read_npz_trajectory(path);
  } else {
    throw Error(path + ": unknown trajectory format '" + ext + "' (use .csv, .yaml, .yml or .npz)");
  }
  if (fps > 0) tr.fps = fps;
  if (!(tr.fps > 0)) tr.fps = kDefaultTrajectoryFps;
  return tr;
}

}  // namespace bimart
