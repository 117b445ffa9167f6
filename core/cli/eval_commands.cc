// bimart eval: the paper's metrics (DESIGN §6, docs/metrics.md) over a folder of sequence
// files (docs/formats.md, "Sequence"), optionally beside a data set's ground truth; a table
// in the paper's column order with the counts behind each share, and JSON on request.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include <ATen/ATen.h>
#include <nlohmann/json.hpp>

#include "core/cli/command.h"
#include "core/cli/sequence_files.h"
#include "core/io/sequence.h"
#include "core/metrics/hand_vertices.h"
#include "core/metrics/multimodality.h"
#include "core/metrics/sequence_metrics.h"
#include "core/object/object_cache.h"
#include "core/object/object_io.h"
#include "core/runtime/blas.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/parallel.h"
#include "core/util/progress.h"

namespace bimart::cli {
namespace {

namespace fs = std::filesystem;

struct SetResult {
  std::string label, folder;
  std::vector<std::string> files;
  std::vector<SequenceMetrics> sequences;
  std::vector<double> mul;  // per trajectory with >= 2 samples
  size_t trajectories = 0;
  std::vector<MetricResult> table;
};

SequenceData sequence_data(const Sequence& s, bool keypoints) {
  SequenceData d;
  d.name = s.name;
  d.object_states = s.object_states;
  d.hand_vertices = hand_vertices(s.hands);
  if (keypoints && s.contact_maps.defined() && s.basis_hit_indices.defined()) {
    d.hand_keypoints = hand_keypoints(s.hands);
    d.contact_maps = s.contact_maps;
    d.basis_hit_indices = s.basis_hit_indices;
  }
  return d;
}

// Samples of one trajectory share the object and the object states exactly.
std::string trajectory_key(const Sequence& s, const std::string& object_path) {
  const at::Tensor st = s.object_states.to(at::kFloat).contiguous();
  const std::string bytes(static_cast<const char*>(st.data_ptr()), static_cast<size_t>(st.nbytes()));
  return object_path + '\n' + std::to_string(std::hash<std::string>{}(bytes)) + '\n' +
         std::to_string(st.size(0));
}

SetResult evaluate_set(const std::string& label, const std::string& folder, const std::string& split,
                       int threads, bool progress, ObjectCache& objects) {
  SetResult r;
  r.label = label;
  r.folder = folder;
  r.files = sequence_files(folder, split);
  const size_t n = r.files.size();
  r.sequences.resize(n);
  std::vector<std::string> keys(n);
  {
    ProgressBar bar(label, n, progress);
    parallel_for(n, threads, [&](size_t i) {
      const Sequence s = read_sequence(r.files[i]);
      const std::string object_path = resolve_object_path(s, r.files[i]);
      const auto entry = objects.get(object_path);
      r.sequences[i] = evaluate_sequence(entry->object, *entry->distance, sequence_data(s, true));
      if (r.sequences[i].name.empty()) r.sequences[i].name = fs::path(r.files[i]).stem().string();
      keys[i] = trajectory_key(s, object_path);
      bar.step();
    });
  }
  // Mul: trajectories with several samples, files re-read (vertices are not kept in memory).
  std::map<std::string, std::vector<size_t>> groups;
  for (size_t i = 0; i < n; ++i) groups[keys[i]].push_back(i);
  r.trajectories = groups.size();
  std::vector<std::vector<size_t>> multi;
  for (auto& [key, members] : groups)
    if (members.size() >= 2) multi.push_back(members);
  r.mul.resize(multi.size());
  parallel_for(multi.size(), threads, [&](size_t g) {
    std::vector<at::Tensor> samples;
    for (size_t i : multi[g]) samples.push_back(hand_vertices(read_sequence(r.files[i]).hands));
    r.mul[g] = multimodality(samples);
  });
  r.table = aggregate_metrics(r.sequences, r.mul);
  return r;
}

std::string cell(const MetricResult& m) {
  if (!std::isfinite(m.value)) return "-";
  if (m.frame_share) return fmt::format("{:.2f} ({}/{})", m.value, m.numerator, m.denominator);
  return fmt::format("{:.3f}", m.value);
}

void print_table(const std::vector<SetResult>& sets) {
  const auto& cols = sets.front().table;
  std::vector<size_t> width;
  std::string header = fmt::format("{:<24}", "");
  for (size_t c = 0; c < cols.size(); ++c) {
    size_t w = cols[c].name.size() + 2;
    for (const auto& s : sets) w = std::max(w, cell(s.table[c]).size());
    width.push_back(w + 2);
    header += fmt::format("{:>{}}", cols[c].name + (cols[c].higher_is_better ? " ↑" : " ↓"), width[c]);
  }
  std::cout << header << "\n";
  for (const auto& s : sets) {
    std::string row = fmt::format("{:<24}", fmt::format("{} ({})", s.label, s.sequences.size()));
    for (size_t c = 0; c < cols.size(); ++c) row += fmt::format("{:>{}}", cell(s.table[c]), width[c]);
    std::cout << row << "\n";
  }
  std::cout << "units: Mul cm, Accel cm/frame², Pen/Con/Art % of frames (passing/considered), CM cm; "
               "'-' = nothing to measure\n";
  for (const auto& s : sets)
    std::cout << fmt::format("{}: {} sequences, {} trajectories, {} with several samples (Mul)\n", s.label,
                             s.sequences.size(), s.trajectories, s.mul.size());
}

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json to_json(const SetResult& s) {
  nlohmann::json j;
  j["folder"] = s.folder;
  j["sequences"] = s.sequences.size();
  j["trajectories"] = s.trajectories;
  j["trajectories_with_samples"] = s.mul.size();
  for (const auto& m : s.table) {
    nlohmann::json c{{"name", m.name}, {"value", number(m.value)}, {"unit", m.unit},
                     {"higher_is_better", m.higher_is_better}, {"num_sequences", m.num_sequences}};
    if (m.frame_share) {
      c["numerator"] = m.numerator;
      c["denominator"] = m.denominator;
    }
    j["metrics"].push_back(c);
  }
  for (size_t i = 0; i < s.sequences.size(); ++i) {
    const SequenceMetrics& m = s.sequences[i];
    auto count = [](const FrameCount& c) { return nlohmann::json::array({c.hits, c.frames}); };
    j["per_sequence"].push_back({{"file", s.files[i]}, {"name", m.name}, {"frames", m.frames},
                                 {"accel_cm", number(100 * m.accel)}, {"pen_1cm", count(m.pen_1cm)},
                                 {"pen_5mm", count(m.pen_5mm)}, {"con", count(m.contact)},
                                 {"art", count(m.articulation)}, {"cm_cm", number(100 * m.contact_map)}});
  }
  return j;
}

struct EvalOptions {
  std::string folder, ground_truth, split, json, mano_left, mano_right;
  int threads = 0;
  bool quiet = false;
};

int eval(const EvalOptions& o) {
  if (o.folder.empty() && o.ground_truth.empty())
    throw Error("bimart eval: give a folder of sequences and/or --ground-truth DATASET");
  const int threads = resolve_threads(o.threads);
  // One sequence per thread: libtorch's own intra-op threads would only oversubscribe.
  runtime::set_threads(1);
  if (!o.mano_left.empty() || !o.mano_right.empty()) set_posing_hand_models(o.mano_left, o.mano_right);
  const bool progress = !o.quiet;
  ObjectCache objects;
  std::vector<SetResult> sets;
  if (!o.folder.empty()) sets.push_back(evaluate_set("generated", o.folder, o.split, threads, progress, objects));
  if (!o.ground_truth.empty())
    sets.push_back(evaluate_set("ground truth", o.ground_truth, o.split, threads, progress, objects));
  print_table(sets);
  if (!o.json.empty()) {
    nlohmann::json j;
    j["threads"] = threads;
    if (!o.split.empty()) j["split"] = o.split;
    for (const auto& s : sets) j[s.label == "generated" ? "generated" : "ground_truth"] = to_json(s);
    write_file_atomically(o.json, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
    std::cout << "wrote " << o.json << "\n";
  }
  return 0;
}

}  // namespace

void add_eval_commands(CLI::App& app, Commands& out) {
  static EvalOptions o;
  CLI::App* cmd = app.add_subcommand(
      "eval", "the paper's metrics (Mul, Accel, Pen 1cm/5mm, Con, Art, CM) over a folder of sequence files");
  cmd->add_option("folder", o.folder, "folder of generated sequences (*.npz, searched recursively)");
  cmd->add_option("--ground-truth", o.ground_truth, "a data set folder whose sequences are evaluated as ground truth");
  cmd->add_option("--split", o.split,
                  "only the files listed under this key of <folder>/manifest.json (e.g. test)");
  cmd->add_option("--json", o.json, "also write the results (table and per-sequence counts) to this JSON file");
  cmd->add_option("--threads", o.threads, "worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--mano-left", o.mano_left, "left hand model .npz to pose the hands with (default: the shipped hand)");
  cmd->add_option("--mano-right", o.mano_right, "right hand model .npz (give both; e.g. converted MANO for ARCTIC data)");
  cmd->add_flag("--quiet", o.quiet, "no progress bar");
  out.push_back({cmd, [] { return eval(o); }, false});
}

}  // namespace bimart::cli
