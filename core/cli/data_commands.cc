// bimart data synth | stats: make a synthetic data set; normalisation statistics of one.
#include <fmt/format.h>

#include <iostream>

#include "core/cli/command.h"
#include "core/cli/data_stats_command.h"
#include "core/object/families/families.h"
#include "core/synth/dataset.h"
#include "core/util/text.h"

namespace bimart::cli {

void add_data_commands(CLI::App& app, Commands& out) {
  CLI::App* data = app.add_subcommand("data", "training data: synthesise a data set, its statistics");
  data->require_subcommand(1);

  static SynthOptions o;
  static bool quiet = false;
  CLI::App* synth = data->add_subcommand(
      "synth", "write a synthetic data set: objects, grab/use trajectories, bimanual hands, manifest");
  synth->add_option("--out", o.out, "data set folder (created; must be empty unless --force)")->required();
  synth->add_option("--seed", o.seed, "data set seed: the same seed writes byte-identical files")->capture_default_str();
  synth->add_option("--categories", o.categories, "object categories (default: all): " + join(object_categories(), ", "))
      ->delimiter(',');
  synth->add_option("--train-objects", o.train_objects, "object instances per category in the train split")
      ->capture_default_str()->check(CLI::PositiveNumber);
  synth->add_option("--test-objects", o.test_objects, "object instances per category in the test split")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  synth->add_option("--sequences", o.sequences_per_object, "sequences per object (alternating grab and use)")
      ->capture_default_str()->check(CLI::PositiveNumber);
  synth->add_option("--min-frames", o.trajectory.min_frames, "shortest sequence (frames)")->capture_default_str();
  synth->add_option("--max-frames", o.trajectory.max_frames, "longest sequence (frames)")->capture_default_str();
  synth->add_option("--fps", o.trajectory.fps, "frames per second")->capture_default_str();
  synth->add_option("--preview", o.preview, "render this many sequences (4 frames each) to OUT/preview/*.png")
      ->capture_default_str();
  synth->add_option("--mano-left", o.mano_left, "left hand model .npz (default: the shipped procedural hand)");
  synth->add_option("--mano-right", o.mano_right, "right hand model .npz (default: the shipped procedural hand)");
  synth->add_option("--threads", o.threads, "worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
  synth->add_flag("--force", o.force, "replace the data set already in --out");
  synth->add_flag("--quiet", quiet, "no progress bar");
  out.push_back({synth,
                 [] {
                   o.progress = !quiet;
                   const SynthSummary s = synthesize_dataset(o);
                   std::cout << fmt::format(
                       "wrote {}: {} objects, {} train + {} test sequences, {} frames, in {:.1f} s{}\n", o.out,
                       s.objects, s.train, s.test, s.frames, s.seconds,
                       s.failed ? fmt::format(" ({} sequences skipped, see the warnings)", s.failed) : "");
                   for (const auto& p : s.previews) std::cout << "preview: " << p << "\n";
                   return 0;
                 },
                 false});
  add_data_stats_command(*data, out);
}

}  // namespace bimart::cli
