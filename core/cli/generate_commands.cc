// bimart generate DATASET: runs a generating pipeline (default pipelines/generate_eval.yaml)
// over the fixed evaluation windows of a data set split, several samples each, and writes
// sequence files that `bimart eval` groups by trajectory (docs/training.md, "Evaluation").
//
// The evaluation set: one window of `--window` frames (64) from the middle of every
// sequence of the split, ordered round-robin over categories and within them over the kinds
// (so `--limit N` still covers every category and both kinds), each written with its
// ground-truth hands to DIR/ground_truth/.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include <ATen/ATen.h>
#include <nlohmann/json.hpp>

#include "core/cli/command.h"
#include "core/data/manifest.h"
#include "core/features/hand_features.h"
#include "core/hand/hand_motion.h"
#include "core/io/sequence.h"
#include "core/metrics/hand_vertices.h"
#include "core/pipeline/graph.h"
#include "core/pipeline/registry.h"
#include "core/pipeline/stage.h"
#include "core/pipeline/runner.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/progress.h"

namespace bimart::cli {
namespace {

namespace fs = std::filesystem;

struct GenerateArgs {
  std::string dataset, split = "test", out, pipeline = "pipelines/generate_eval.yaml";
  int samples = 10, window = 64;
  long long limit = 0, seed = 0;
  bool resume = false;
  std::vector<std::string> overrides;
};

struct EvalWindow {
  std::string name, category, source;
  std::int64_t start = 0, length = 0;
};

HandMotion slice_hands(const HandMotion& m, std::int64_t start, std::int64_t length) {
  HandMotion out = m;
  for (auto& h : out.hands) {
    h.rot = h.rot.slice(0, start, start + length).contiguous();
    h.pose = h.pose.slice(0, start, start + length).contiguous();
    h.trans = h.trans.slice(0, start, start + length).contiguous();
  }
  if (m.vertices.defined()) out.vertices = m.vertices.slice(1, start, start + length).contiguous();
  return out;
}

struct WindowSource {
  std::string category, kind, file;
};

// The first of every list, then the second of every list, and so on.
std::vector<std::string> round_robin(const std::vector<std::vector<std::string>>& lists) {
  std::vector<std::string> out;
  for (std::size_t i = 0;; ++i) {
    bool any = false;
    for (const auto& v : lists)
      if (i < v.size()) {
        out.push_back(v[i]);
        any = true;
      }
    if (!any) return out;
  }
}

// Round-robin over categories (sorted); within each, round-robin over the kinds (grab,
// use), sequences by name within each kind. So `--limit N` covers every category and, from
// N = 2 × categories on, both kinds (the Art metric needs "use" windows).
std::vector<std::string> category_order(const std::vector<WindowSource>& files) {
  std::map<std::string, std::map<std::string, std::vector<std::string>>> by;  // category → kind → files
  for (const auto& f : files) by[f.category][f.kind].push_back(f.file);
  std::vector<std::vector<std::string>> per_category;
  for (auto& [c, kinds] : by) {
    std::vector<std::vector<std::string>> per_kind;
    for (auto& [k, v] : kinds) {
      std::sort(v.begin(), v.end());
      per_kind.push_back(v);
    }
    per_category.push_back(round_robin(per_kind));
  }
  return round_robin(per_category);
}

int run_generate(const GenerateArgs& a) {
  if (a.out.empty()) throw Error("--out is required");
  const DatasetManifest manifest = read_manifest(a.dataset);
  const std::vector<std::string> files = split_files(manifest, a.dataset, a.split);
  if (files.empty()) throw Error(a.dataset + ": the " + a.split + " split is empty");

  // The pipeline: which stages read the trajectory and which write sequences.
  GraphFile proto = GraphFile::load(a.pipeline);
  std::string trajectory_id;
  std::vector<std::string> exports;
  std::string motion_id, fit_id;
  for (const auto& st : proto.stages) {
    if (st.use == "trajectory.sequence") trajectory_id = st.id;
    if (st.use == "export.sequence") exports.push_back(st.id);
    if (st.use.rfind("motion.", 0) == 0) motion_id = st.id;
    if (st.use == "refine.mano_fit") fit_id = st.id;
  }
  if (trajectory_id.empty())
    throw Error(a.pipeline + ": bimart generate needs a trajectory.sequence stage to feed the windows to");
  if (exports.empty()) throw Error(a.pipeline + ": bimart generate needs at least one export.sequence stage");
  // The samples: the pipeline's variable `samples` when it declares one, else the
  // `samples` parameter of every stage that has one (the diffusion stages).
  bool declares_samples_var = false;
  for (const auto& v : proto.vars) declares_samples_var |= v.name == "samples";
  std::vector<std::string> sampling_ids;
  if (!declares_samples_var)
    for (const auto& st : proto.stages)
      if (const StageEntry* e = Registry::global().find(st.use); e && e->spec.find_param("samples"))
        sampling_ids.push_back(st.id);

  // The evaluation windows, written with their ground truth.
  const fs::path out(a.out);
  const fs::path gt_dir = out / "ground_truth";
  std::vector<WindowSource> by_category;
  std::map<std::string, Sequence> loaded;
  for (const auto& f : files) {
    Sequence s = read_sequence(f);
    by_category.push_back({s.category, s.kind, f});
    loaded[f] = std::move(s);
  }
  std::vector<std::string> order = category_order(by_category);
  if (a.limit > 0 && static_cast<std::size_t>(a.limit) < order.size()) order.resize(static_cast<std::size_t>(a.limit));
  std::vector<EvalWindow> windows;
  for (const auto& f : order) {
    const Sequence& s = loaded.at(f);
    EvalWindow w;
    w.name = s.name;
    w.category = s.category;
    w.length = std::min<std::int64_t>(a.window, s.num_frames());
    w.start = (s.num_frames() - w.length) / 2;
    w.source = (gt_dir / (s.name + fmt::format("_f{:03d}.npz", w.start))).string();
    Sequence g = s;
    g.name = fs::path(w.source).stem().string();
    g.object_states = s.object_states.slice(0, w.start, w.start + w.length).contiguous();
    g.hands = slice_hands(s.hands, w.start, w.length);
    g.contact_maps = at::Tensor();
    g.basis_hit_indices = at::Tensor();
    g.object = relative_object_path(resolve_object_path(s, f), w.source);
    fs::create_directories(gt_dir);
    write_sequence(g, w.source);
    windows.push_back(w);
  }
  std::map<std::string, int> categories;
  for (const auto& w : windows) ++categories[w.category];
  log::info("generate: {} windows of up to {} frames from {} {} sequences ({} categories), {} samples each, pipeline {}",
            windows.size(), a.window, files.size(), a.split, categories.size(), a.samples, a.pipeline);

  nlohmann::json summary;
  summary["dataset"] = a.dataset;
  summary["split"] = a.split;
  summary["pipeline"] = a.pipeline;
  summary["samples"] = a.samples;
  summary["seed"] = a.seed;
  summary["window"] = a.window;
  double residual_sum = 0;
  std::int64_t residual_count = 0;
  const auto t0 = std::chrono::steady_clock::now();
  ProgressBar bar("generate", windows.size(), true);
  std::size_t reused = 0;
  // What a window's record must match to be kept by --resume.
  const nlohmann::json run_key{{"pipeline", a.pipeline}, {"set", a.overrides}, {"seed", a.seed}, {"samples", a.samples}};
  for (const auto& w : windows) {
    nlohmann::json jw{{"name", w.name}, {"category", w.category}, {"start", w.start}, {"frames", w.length},
                      {"ground_truth", fs::relative(w.source, out).string()}};
    const std::string stem = fs::path(w.source).stem().string();
    // Each finished window leaves a record; --resume keeps a window whose record and sample
    // files all exist (every window's run is seeded alone, so the result is the same).
    const fs::path record = out / "windows" / (stem + ".json");
    if (a.resume && fs::exists(record)) {
      bool complete = true;
      for (const auto& e : exports)
        for (int k = 0; k < a.samples; ++k)
          complete = complete && fs::exists(out / e / fmt::format("{}_s{:02d}.npz", stem, k));
      if (complete) {
        std::ifstream in(record);
        const nlohmann::json kept = nlohmann::json::parse(in, nullptr, false);
        if (!kept.is_discarded() && kept.contains("run") && kept["run"] == run_key) {
          jw = kept;
          jw.erase("run");
          for (const auto& mm : jw.value("fit_residual_mm", nlohmann::json::array())) {
            residual_sum += mm.get<double>() / 1e3;
            ++residual_count;
          }
          summary["windows"].push_back(jw);
          ++reused;
          bar.step();
          continue;
        }
      }
    }
    // One run per window draws all its samples as one batch; each export.sequence stage
    // writes one file per sample (stages/samples.h).
    GraphFile file = proto;
    if (declares_samples_var) file.set_var("samples", std::to_string(a.samples), "--samples");
    for (const auto& id : sampling_ids) file.apply_override(id + ".samples=" + std::to_string(a.samples));
    for (const auto& o : a.overrides) file.apply_override(o);
    file.apply_override(trajectory_id + ".path=" + w.source);
    for (const auto& e : exports)
      file.apply_override(e + ".path=" + (out / e / (stem + "_s{sample:02d}.npz")).string());
    file.seed = static_cast<std::uint64_t>(a.seed);
    const Graph g = validate(file, Registry::global());
    const RunResult r = run_graph(g);
    if (!motion_id.empty() && !fit_id.empty()) {
      // Keypoint-to-MANO residual per sample: generated H against the fitted hands' keypoints.
      // A motion stage that knows nothing of samples (motion.ground_truth) writes one.
      const std::string key = motion_id + ".hand_keypoints";
      const at::Tensor X = r.context.has(key + "_samples") ? r.context.get<at::Tensor>(key + "_samples")
                                                            : r.context.get<at::Tensor>(key).unsqueeze(0);
      const at::Tensor states = r.context.get<at::Tensor>(trajectory_id + ".object_states");
      const auto& fits = r.context.get<std::vector<HandMotion>>(fit_id + ".hand_samples");
      for (std::size_t k = 0; k < fits.size(); ++k) {
        const at::Tensor H = hand_features_to_world(X[static_cast<std::int64_t>(k)], states).positions;  // [2, N, J, 3]
        const double res = (H - hand_keypoints(fits[k])).norm(2, -1).mean().item<double>();
        jw["fit_residual_mm"].push_back(1e3 * res);
        residual_sum += res;
        ++residual_count;
      }
    }
    nlohmann::json rec = jw;
    rec["run"] = run_key;
    fs::create_directories(record.parent_path());
    write_file_atomically(record.string(), [&](std::ostream& o) { o << rec.dump(2) << "\n"; });
    bar.step();
    summary["windows"].push_back(jw);
  }
  if (reused > 0) log::info("generate: {} of {} windows were already done (--resume)", reused, windows.size());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary["seconds"] = seconds;
  if (residual_count > 0) summary["mean_fit_residual_mm"] = 1e3 * residual_sum / residual_count;
  const std::string summary_path = (out / "generate.json").string();
  write_file_atomically(summary_path, [&](std::ostream& o) { o << summary.dump(2) << "\n"; });
  std::cout << fmt::format("{} windows x {} samples in {:.0f} s", windows.size(), a.samples, seconds);
  if (residual_count > 0) std::cout << fmt::format(", mean keypoint-to-MANO fit residual {:.2f} mm", 1e3 * residual_sum / residual_count);
  std::cout << "\n";
  for (const auto& e : exports)
    std::cout << "wrote " << (out / e).string() << "  (bimart eval " << (out / e).string() << ")\n";
  std::cout << "wrote " << gt_dir.string() << " (the ground truth of the windows)\n";
  std::cout << "wrote " << summary_path << "\n";
  return 0;
}

}  // namespace

void add_generate_commands(CLI::App& app, Commands& out) {
  static GenerateArgs a;
  CLI::App* cmd = app.add_subcommand("generate", "generate samples for a data set's evaluation windows (docs/training.md)");
  cmd->add_option("dataset", a.dataset, "data set folder (manifest.json)")->required()->check(CLI::ExistingDirectory);
  cmd->add_option("--split", a.split, "train or test")->check(CLI::IsMember({"train", "test"}));
  cmd->add_option("--samples", a.samples, "samples per window")->check(CLI::Range(1, 1000));
  cmd->add_option("--out", a.out, "output folder")->required();
  cmd->add_option("--limit", a.limit, "at most this many windows (round-robin over categories)")->check(CLI::PositiveNumber);
  cmd->add_option("--pipeline", a.pipeline, "pipeline YAML with a trajectory.sequence and export.sequence stages")
      ->check(CLI::ExistingFile);
  cmd->add_option("--window", a.window, "frames per window")->check(CLI::Range(2, 100000));
  cmd->add_option("--set", a.overrides, "override a parameter: stage.param=value (repeatable)");
  cmd->add_flag("--resume", a.resume,
                "keep the windows an earlier run of the same command finished (DIR/windows/*.json and all their samples)");
  cmd->add_option("--seed", a.seed, "seed of every window's run (its samples are drawn as one batch)")->check(CLI::NonNegativeNumber);
  out.push_back({cmd, [] { return run_generate(a); }});
}

}  // namespace bimart::cli
