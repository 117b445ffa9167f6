// A motion sequence file (.npz; docs/formats.md, "Sequence"): the object it uses, the
// frame rate, the object's 7-DoF states and both hands in the ARCTIC field layout. The
// one format that data synthesis, generation, refinement and `bimart eval` all read and
// write. Writing is atomic.
#pragma once

#include <cstdint>
#include <string>

#include <ATen/core/Tensor.h>

#include "core/hand/hand_motion.h"

namespace bimart {

// The longest sequence anything reads or makes: 10^6 frames (9 h at 30 fps). Longer
// requests are refused up front instead of failing in an allocator.
constexpr std::int64_t kMaxFrames = 1000000;

struct Sequence {
  std::string name;      // e.g. "laptop_s0003_use_012"
  // Where the object lives: a path to an object folder or YAML (core/object/object_io.h),
  // relative to the sequence file's folder unless absolute.
  std::string object;
  std::string category;  // object family, "" when unknown
  std::string kind;      // "grab", "use", or "" (free text for other sources)
  double fps = 30.0;
  at::Tensor object_states;  // [N, 7] float32, [angle, rx, ry, rz, tx, ty, tz]
  HandMotion hands;          // N frames; `vertices` [2, N, V, 3] optional
  // Optional, for the CM metric of generated sequences: the contact maps that conditioned
  // the motion [N, 2, 1024] float32 (m) and the encoder's basis_hit_indices [N, 1024] int64.
  at::Tensor contact_maps;
  at::Tensor basis_hit_indices;

  std::int64_t num_frames() const { return object_states.defined() ? object_states.size(0) : 0; }
  // Throws bimart::Error naming the field when shapes disagree or values are not finite.
  void validate() const;
};

// Throws bimart::Error naming the file and key on any problem.
Sequence read_sequence(const std::string& path);
void write_sequence(const Sequence& sequence, const std::string& path);
// The object path resolved against the sequence file's folder.
std::string resolve_object_path(const Sequence& sequence, const std::string& sequence_path);
// The inverse: `object_path` as a Sequence stores it for a file at `sequence_path`:
// relative to that file's folder when at most two `..` lead there, else absolute.
std::string relative_object_path(const std::string& object_path, const std::string& sequence_path);

}  // namespace bimart
