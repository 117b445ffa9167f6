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
#include <sstream>
#include <thread>

#include <ATen/ATen.h>
#include <nlohmann/json.hpp>

#include "core/cli/command.h"
#include "core/cli/sequence_files.h"
#include "core/io/sequence.h"
#include "core/metrics/frame_report.h"
#include "core/metrics/hand_vertices.h"
#include "core/metrics/metrics_json.h"
#include "core/metrics/multimodality.h"
#include "core/metrics/sequence_metrics.h"
#include "core/object/object_cache.h"
#include "core/object/object_io.h"
#include "core/runtime/blas.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/output_path.h"
#include "core/util/parallel.h"
#include "core/util/progress.h"

namespace bimart::cli {
namespace {

namespace fs = std::filesystem;

struct SetResult : MetricsSet {
  std::string label;
  std::vector<std::string> frame_csv;  // per evaluated file, its --frames rows (when asked)
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
                       int threads, bool keep_going, ObjectCache& objects, bool frame_rows) {
  SetResult r;
  r.label = label;
  r.folder = folder;
  std::vector<std::string> files = sequence_files(folder, split);
  const size_t total = files.size();
  std::vector<SequenceMetrics> sequences(total);
  std::vector<std::string> all_keys(total), errors(total), csv(total);
  {
    ProgressBar bar(label, total, true);
    parallel_for(total, threads, [&](size_t i) {
      try {
        const Sequence s = read_sequence(files[i]);
        const auto entry = sequence_object(objects, s, files[i]);
        try {
          const SequenceData d = sequence_data(s, true);
          sequences[i] = evaluate_sequence(entry->object, *entry->distance, d);
          if (frame_rows) {
            const auto hands = posing_hand_models();
            std::ostringstream rows;
            write_frame_rows_csv(rows, fs::relative(files[i], folder).string(),
                                 hand_frame_rows(*entry->distance, d.object_states, d.hand_vertices,
                                                 {&(*hands)[0], &(*hands)[1]}),
                                 false);
            csv[i] = rows.str();
          }
        } catch (const Error& e) {
          throw in_sequence_file(files[i], e);
        }
        if (sequences[i].name.empty()) sequences[i].name = fs::path(files[i]).stem().string();
        all_keys[i] = trajectory_key(s, resolve_object_path(s, files[i]));
      } catch (const Error& e) {
        if (!keep_going) throw;
        errors[i] = e.what();  // one slot per file: no lock needed
      }
      bar.step();
    });
  }
  // --keep-going: the bad files are listed and left out; the rest is evaluated as usual.
  std::vector<std::string> keys;
  for (size_t i = 0; i < total; ++i) {
    if (!errors[i].empty()) {
      r.skipped.push_back({files[i], errors[i]});
      log::warn("skipped {}", errors[i]);
      continue;
    }
    r.files.push_back(files[i]);
    r.sequences.push_back(sequences[i]);
    r.frame_csv.push_back(std::move(csv[i]));
    keys.push_back(all_keys[i]);
  }
  const size_t n = r.files.size();
  if (n == 0) throw Error(folder + ": every one of the " + std::to_string(total) + " sequence files was refused");
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
    for (size_t i : multi[g]) {
      try {
        samples.push_back(hand_vertices(read_sequence(r.files[i]).hands));
      } catch (const Error& e) {
        throw in_sequence_file(r.files[i], e);
      }
    }
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
  std::cout << "units: Mul cm, Accel cm/frame², Pen/Con/Art % of frames (passing/considered), Depth mm (mean over contact frames), CM cm, Implaus and Cavity % of frames; "
               "'-' = nothing to measure\n";
  for (const auto& s : sets)
    std::cout << fmt::format("{}: {} sequences, {} trajectories, {} with several samples (Mul){}\n", s.label,
                             s.sequences.size(), s.trajectories, s.mul.size(),
                             s.skipped.empty() ? "" : fmt::format("; {} files skipped (bad input)", s.skipped.size()));
}

struct EvalOptions {
  std::string folder, ground_truth, split, json, mano_left, mano_right, frames;
  bool keep_going = false;
};

int eval(const EvalOptions& o) {
  if (o.folder.empty() && o.ground_truth.empty())
    throw Error("bimart eval: give a folder of sequences and/or --ground-truth DATASET");
  const int threads = resolve_threads(0);  // the global --threads, else all cores
  if (!o.json.empty()) check_output_file(o.json);
  if (!o.frames.empty()) check_output_file(o.frames);
  // One sequence per thread: libtorch's own intra-op threads would only oversubscribe.
  runtime::set_threads(1);
  if (!o.mano_left.empty() || !o.mano_right.empty()) set_posing_hand_models(o.mano_left, o.mano_right);
  ObjectCache objects;
  std::vector<SetResult> sets;
  if (!o.folder.empty()) sets.push_back(evaluate_set("generated", o.folder, o.split, threads, o.keep_going, objects, !o.frames.empty()));
  if (!o.ground_truth.empty())
    sets.push_back(evaluate_set("ground truth", o.ground_truth, o.split, threads, o.keep_going, objects, !o.frames.empty()));
  print_table(sets);
  if (!o.frames.empty()) {
    write_file_atomically(o.frames, [&](std::ostream& out) {
      out << "set,";
      write_frame_rows_csv(out, "", {}, true);
      for (const auto& s : sets)
        for (const auto& rows : s.frame_csv) {
          std::istringstream in(rows);
          for (std::string line; std::getline(in, line);) out << (s.label == "generated" ? "generated," : "ground_truth,") << line << "\n";
        }
    });
    std::cout << "wrote " << o.frames << "\n";
  }
  size_t skipped = 0;
  for (const auto& s : sets) skipped += s.skipped.size();
  if (!o.json.empty()) {
    nlohmann::json j;
    j["threads"] = threads;
    if (!o.split.empty()) j["split"] = o.split;
    for (const auto& s : sets) j[s.label == "generated" ? "generated" : "ground_truth"] = metrics_json(s);
    write_file_atomically(o.json, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
    std::cout << "wrote " << o.json << "\n";
  }
  if (skipped) {
    std::cout << skipped << " files skipped:\n";
    for (const auto& s : sets)
      for (const auto& [file, why] : s.skipped) std::cout << "  " << why << "\n";
  }
  return skipped ? 1 : 0;  // the table holds the rest; the exit code says some input was bad
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
  cmd->add_option("--frames", o.frames,
                  "also write one CSV row per frame and hand: depth in the object, the deepest vertex's joint and "
                  "part, cavity depth, why implausible (docs/metrics.md)");
  cmd->add_option("--mano-left", o.mano_left, "left hand model .npz to pose the hands with (default: the shipped hand)");
  cmd->add_option("--mano-right", o.mano_right, "right hand model .npz (give both; e.g. converted MANO for ARCTIC data)");
  cmd->add_flag("--keep-going", o.keep_going,
                "skip files that fail (listed at the end and in the JSON) and evaluate the rest; exit code 1 "
                "when any was skipped");
  out.push_back({cmd, [] { return eval(o); }, false});
}

}  // namespace bimart::cli
