// `bimart data synth`: a whole synthetic data set (DESIGN §7) — procedural objects of every
// category, grab and use trajectories, bimanual hand motion — written as sequence files
// (docs/formats.md, "Sequence") with the object meshes and a manifest whose train/test
// split is by object instance (core/data/manifest.h). Deterministic in the seed, parallel
// over sequences, with progress. See docs/data.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/synth/interaction.h"
#include "core/synth/trajectory.h"

namespace bimart {

struct SynthOptions {
  std::string out;                      // the data set folder
  std::vector<std::string> categories;  // empty = every procedural category
  int train_objects = 5;                // object instances per category in the train split
  int test_objects = 1;                 // ... and in the test split
  int sequences_per_object = 13;        // alternating grab and use
  std::uint64_t seed = 1;
  int threads = 0;                      // 0 = all cores
  bool progress = true;
  bool force = false;                   // replace an existing data set in `out`
  int preview = 0;                      // sequences rendered to out/preview/<name>.png
  std::string mano_left, mano_right;    // hand model files; empty = the shipped models
  TrajectoryOptions trajectory;
  InteractionOptions interaction;
};

struct SynthSummary {
  int objects = 0;
  int train = 0, test = 0;  // sequences written
  int failed = 0;           // sequences given up (no valid motion after retries)
  long frames = 0;
  double seconds = 0;
  std::vector<std::string> previews;  // PNG files written
};

SynthSummary synthesize_dataset(const SynthOptions& options);

// Four frames of a sequence (grasp, two during the motion, release) tiled into one PNG.
void render_sequence_preview(const ArticulatedObject& object, const Trajectory& trajectory,
                             const HandMotion& hands, const std::array<const HandModel*, 2>& models,
                             const std::string& png, int size = 320);

}  // namespace bimart
