// Directing commands (docs/directing.md). `bimart edit SAMPLE.npz --frames A:B`: an earlier
// sample with a stretch redrawn. Runs a pipeline (the default one unless --pipeline) on the sample
// itself as the trajectory, with `trajectory.redraw` set: the frames outside A..B come out
// exactly as they were, the stretch is sampled anew and joined to them. `bimart constraints
// SAMPLES --hands FILE`: how well each constraint of FILE holds in each sample.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/cli/command.h"
#include "core/cli/common_options.h"
#include "core/cli/pipeline_commands.h"
#include "core/directing/constraint_report.h"
#include "core/export/scene_source.h"
#include "core/util/data_path.h"
#include "core/util/error.h"

namespace bimart::cli {
namespace {

struct EditArgs {
  std::string sample, frames, pipeline = "pipelines/bimart.yaml", out;
  std::vector<std::string> overrides;
  bool keep_contacts = false;
  int blend = 8;
  std::uint64_t seed = 0;
  bool has_seed = false;
};

// "40:90" (both included), "40:" (to the end), ":90", or "" (with --keep-contacts: all).
std::string redraw_value(const std::string& text) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) throw Error("--frames: write FIRST:LAST (both included), e.g. 40:90; got '" + text + "'");
  const auto number = [&](const std::string& s, long fallback) {
    if (s.empty()) return fallback;  // the stage checks the range against the sample
    std::size_t used = 0;
    long v = -1;
    try {
      v = std::stol(s, &used);
    } catch (const std::exception&) {
    }
    if (used != s.size() || v < 0) throw Error("--frames: '" + s + "' is not a frame number (FIRST:LAST, e.g. 40:90)");
    return v;
  };
  const long a = number(text.substr(0, colon), 0), b = number(text.substr(colon + 1), -1);  // -1: the last
  return fmt::format("[{}, {}]", a, b);
}

int edit(const EditArgs& e) {
  if (e.frames.empty() && !e.keep_contacts) throw Error("give --frames FIRST:LAST (or --keep-contacts to redraw all motion)");
  PipelineArgs pa;
  pa.pipeline = find_data_file(e.pipeline);
  pa.overrides = {"trajectory.path=" + e.sample, fmt::format("trajectory.redraw_blend={}", e.blend)};
  if (!e.frames.empty()) {
    pa.overrides.push_back("trajectory.redraw=" + redraw_value(e.frames));
  }
  if (e.keep_contacts) pa.overrides.push_back("trajectory.keep_contacts=true");
  pa.overrides.insert(pa.overrides.end(), e.overrides.begin(), e.overrides.end());
  const std::filesystem::path s(e.sample);
  pa.out = !e.out.empty() ? e.out : (s.parent_path() / (s.stem().string() + "_edit")).string();
  pa.samples = 1;
  pa.seed = e.seed;
  pa.has_seed = e.has_seed;
  return run(pa);
}

struct ConstraintsArgs {
  std::vector<std::string> samples;
  std::string hands, mano_left, mano_right;
  bool json = false;
};

// Exit 0 when every constraint holds in every sample, 1 when one does not (the report says which).
int report_constraints(const ConstraintsArgs& a) {
  const auto models = load_export_hands(a.mano_left, a.mano_right);
  nlohmann::json all = nlohmann::json::array();
  bool every = true;
  for (const std::string& path : a.samples) {
    const SceneSource src = load_scene_source(path, models);
    const std::vector<ConstraintCheck> checks = check_constraints(read_hand_constraints_for_sample(a.hands, path, src.sequence.fps), src);
    nlohmann::json js = nlohmann::json::array();
    if (!a.json) std::cout << path << "\n";
    for (const ConstraintCheck& c : checks) {
      every = every && c.holds;
      if (a.json)
        js.push_back({{"asked", c.asked}, {"measured", c.measured}, {"value", c.value}, {"holds", c.holds}});
      else
        std::cout << fmt::format("  {} {}: {}\n", c.holds ? "holds " : "MISSED", c.asked, c.measured);
    }
    all.push_back({{"sample", path}, {"constraints", js}});
  }
  if (a.json) std::cout << all.dump(2) << "\n";
  return every ? 0 : 1;
}

}  // namespace

void add_edit_commands(CLI::App& app, Commands& out) {
  {
    static ConstraintsArgs c;
    CLI::App* cmd = app.add_subcommand("constraints", "how well each hand constraint holds in samples (docs/directing.md)");
    cmd->add_option("samples", c.samples, "sequence files (sample_K.npz of bimart run)")->required()->check(CLI::ExistingFile);
    cmd->add_option("--hands", c.hands, "the trajectory file (or a file with a `hands:` block) the samples were made with")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_flag("--json", c.json, "print the report as JSON");
    cmd->add_option("--mano-left", c.mano_left, "left hand model .npz the samples were made with (default: the shipped hand)");
    cmd->add_option("--mano-right", c.mano_right, "right hand model .npz (give both or neither)");
    out.push_back({cmd, [] { return report_constraints(c); }, false});
  }
  static EditArgs e;
  CLI::App* cmd = app.add_subcommand("edit", "redraw a stretch of an earlier sample, keeping every other frame (docs/directing.md)");
  cmd->add_option("sample", e.sample, "the sample's sequence file (sample_K.npz of bimart run)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--frames", e.frames, "FIRST:LAST, both included: the frames drawn anew (FIRST: = to the end)");
  cmd->add_flag("--keep-contacts", e.keep_contacts, "keep the sample's contact maps everywhere; draw only new motion");
  cmd->add_option("--blend", e.blend, "frames over which the stretch fades in from the kept frames at each join")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--pipeline", e.pipeline, "the pipeline to run (its trajectory stage must be trajectory.file)");
  cmd->add_option("--out", e.out, "output folder (default: next to the sample, SAMPLE_edit)");
  cmd->add_option("--set", e.overrides, "override a parameter: stage.param=value (repeatable)");
  add_seed_option(cmd, e.seed, "seed of the redrawn stretch (default: the pipeline's)")->each([](const std::string&) {
    e.has_seed = true;
  });
  out.push_back({cmd, [] { return edit(e); }});
}

}  // namespace bimart::cli
