// A 7-DoF object trajectory read from a file (docs/trajectories.md): per-frame CSV, YAML or
// sequence .npz, or YAML keyframes sampled at a frame rate. Readers check syntax, types and
// numbers and name the file and line; core/trajectory/validation.h checks a trajectory
// against its object (hinge limits) and the frame-count bounds.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/util/error.h"

namespace bimart {

// The most frames a trajectory file may give or a keyframe file may make: 10 minutes at 30
// fps. A longer input is refused before any frame is made.
constexpr std::int64_t kMaxTrajectoryFrames = 18000;
constexpr double kDefaultTrajectoryFps = 30.0;

// The object a trajectory names: an object folder or YAML (`bimart object make`, `object
// import`) or an ARCTIC template folder, or a procedural category with its seed.
struct ObjectReference {
  std::string path;  // as written: relative to the trajectory file's folder unless absolute
  std::string category;
  std::int64_t seed = 0;
  SourceLocation where;  // where it was named, for messages
  bool empty() const { return path.empty() && category.empty(); }
};

using StateRows = Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>;

struct Trajectory {
  std::string file;
  StateRows states;         // [N, 7] per frame [angle, rx, ry, rz, tx, ty, tz], rad and m
  double fps = 0;           // frames per second
  double start_time = 0;    // time of frame 0 (s): the first key's for keyframes, else 0
  ObjectReference object;   // empty when the file names none
  bool from_keyframes = false;
  // Per frame, the file lines it came from: {line, 0} for a row of a per-frame file, {key
  // line, next key line} of the hinge-angle keys around it for keyframes, {0, 0} for npz.
  std::vector<std::array<int, 2>> lines;
  // Keyframes only: the hinge angle of every key that gives one (rad) and its line.
  std::vector<std::pair<double, int>> angle_keys;

  std::int64_t num_frames() const { return states.rows(); }
  // "file:12: frame 4" or "file:12: frame 40 (t = 1.333 s, between the keys at lines 12 and 20)".
  std::string describe_frame(std::int64_t frame) const;
  SourceLocation frame_location(std::int64_t frame) const;
};

// Reads by extension: .csv, .yaml / .yml (a `frames:` list or `keys:`), .npz (a sequence,
// core/io/sequence.h). `fps` > 0 replaces the file's frame rate (keyframes are sampled at
// it); 0 keeps the file's, else kDefaultTrajectoryFps. Throws bimart::Error naming the file
// and line on any problem; the frame count is checked against [2, kMaxTrajectoryFrames].
Trajectory read_trajectory(const std::string& path, double fps = 0);

}  // namespace bimart
