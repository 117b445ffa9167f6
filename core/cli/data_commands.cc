// bimart data synth | check | stats | turn: make a synthetic data set, check it, normalisation statistics,
// a copy with its objects turned about their hinges.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <iostream>

#include "core/cli/command.h"
#include "core/cli/common_options.h"
#include "core/cli/data_stats_command.h"
#include "core/data/turned_dataset.h"
#include "core/object/families/families.h"
#include "core/synth/dataset.h"
#include "core/synth/dataset_check.h"
#include "core/util/text.h"

namespace bimart::cli {

void add_data_commands(CLI::App& app, Commands& out) {
  CLI::App* data = app.add_subcommand("data", "training data: synthesise a data set, check it, its normalisation statistics");
  data->require_subcommand(1);

  static SynthOptions o;
  CLI::App* synth = data->add_subcommand(
      "synth", "write a synthetic data set: objects, grab/use trajectories, bimanual hands, manifest");
  synth->add_option("--out", o.out, "data set folder (created; must be empty unless --force)")->required();
  add_seed_option(synth, o.seed, "data set seed: the same seed writes byte-identical files (default 1)");
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
  synth->add_flag("--force", o.force, "replace the data set already in --out");
  out.push_back({synth,
                 [] {
                   o.progress = true;  // -q turns every progress bar off
                   const SynthSummary s = synthesize_dataset(o);
                   std::cout << fmt::format(
                       "wrote {}: {} objects, {} train + {} test sequences, {} frames, in {:.1f} s{}\n", o.out,
                       s.objects, s.train, s.test, s.frames, s.seconds,
                       s.failed ? fmt::format(" ({} sequences skipped, see the warnings)", s.failed) : "");
                   for (const auto& p : s.previews) std::cout << "preview: " << p << "\n";
                   return 0;
                 },
                 false});
  static std::string check_folder, check_split = "test", check_left, check_right;
  CLI::App* check = data->add_subcommand(
      "check", "both hands in contact while the object moves, who drives use sequences, hand-hand depth");
  check->add_option("folder", check_folder, "data set folder (with manifest.json)")->required();
  check->add_option("--split", check_split, "train or test")->capture_default_str();
  check->add_option("--mano-left", check_left, "left hand model .npz to pose the hands with (default: shipped)");
  check->add_option("--mano-right", check_right, "right hand model .npz (give both)");
  out.push_back({check,
                 [] {
                   const DatasetCheck c =
                       check_dataset(check_folder, check_split, 0, true, 2, check_left, check_right);
                   const auto pct = [](double a, double b) { return b > 0 ? 100.0 * a / b : 0.0; };
                   std::cout << fmt::format(
                       "{} {} sequences\n"
                       "both hands touch the object: {:.2f} % of the frames where it moves ({}/{})\n"
                       "the left hand drives:        {:.2f} % of the use sequences ({}/{})\n"
                       "deepest hand-hand contact:   {:.2f} mm{}\n",
                       c.sequences, check_split, pct(c.both_touching, c.moving_frames), c.both_touching,
                       c.moving_frames, pct(c.left_drives, c.use_sequences), c.left_drives, c.use_sequences,
                       1000 * c.hand_interpenetration,
                       c.deepest_sequence.empty() ? "" : " (" + c.deepest_sequence + ")");
                   return 0;
                 },
                 false});
  static std::string turn_folder, turn_split = "test", turn_out;
  static std::vector<double> turn_degrees{90};
  static bool turn_force = false;
  CLI::App* turn = data->add_subcommand(
      "turn", "a copy of a split with every object turned about its hinge axis, the world motion unchanged (docs/objects.md)");
  turn->add_option("folder", turn_folder, "data set folder (with manifest.json)")->required();
  turn->add_option("--split", turn_split, "train or test")->capture_default_str();
  turn->add_option("--degrees", turn_degrees,
                   "the turn about the hinge axis (degrees); several (0,90,180,270) write a copy per turn, names "
                   "ending _t<degrees>")
      ->delimiter(',')
      ->capture_default_str();
  turn->add_option("--out", turn_out, "the new data set's folder")->required();
  turn->add_flag("--force", turn_force, "replace the data set already in --out");
  out.push_back({turn,
                 [] {
                   const TurnedDatasetSummary s = write_turned_dataset(turn_folder, turn_split, turn_degrees, turn_out, turn_force);
                   std::cout << fmt::format("wrote {}: {} objects, {} {} sequences turned by {} deg about the hinge axis\n",
                                            turn_out, s.objects, s.sequences, turn_split, fmt::join(turn_degrees, ", "));
                   return 0;
                 },
                 false});
  add_data_stats_command(*data, out);
}

}  // namespace bimart::cli
