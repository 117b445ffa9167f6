// bimart refine: MANO fit and refinement (core/refine, docs/refinement.md) over a folder of
// sequences, from keypoints made of their ground truth — exact, or corrupted as a
// diffusion model errs (core/synth/keypoint_corruption.h) — with the paper's metrics
// before and after, beside the ground truth's. Writes the fitted and the refined
// sequences so that `bimart eval` reads them too.
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <thread>

#include <ATen/ATen.h>
#include <nlohmann/json.hpp>

#include "core/cli/command.h"
#include "core/cli/common_options.h"
#include "core/cli/sequence_files.h"
#include "core/features/hand_features.h"
#include "core/io/sequence.h"
#include "core/metrics/accel.h"
#include "core/metrics/hand_vertices.h"
#include "core/metrics/held_frames.h"
#include "core/metrics/sequence_metrics.h"
#include "core/object/object_cache.h"
#include "core/refine/mano_fit.h"
#include "core/refine/refinement.h"
#include "core/runtime/blas.h"
#include "core/synth/keypoint_corruption.h"
#include "core/util/atomic_file.h"
#include "core/util/data_path.h"
#include "core/util/error.h"
#include "core/util/output_path.h"
#include "core/util/log.h"
#include "core/util/parallel.h"
#include "core/util/progress.h"

namespace bimart::cli {
namespace {

namespace fs = std::filesystem;

struct RefineCliOptions {
  std::string folder, split, out = "out/refine", keypoints = "corrupted", json, mano_left, mano_right;
  std::uint64_t seed = 1;
  int limit = 0, threads = 0;
  bool no_write = false;
  RefineOptions refine;
  ManoFitOptions fit;
  KeypointCorruption corruption;
};

// The rows of the table, in order.
enum Row { kTruth, kTruthKeypoints, kInputKeypoints, kFit, kRefined, kRows };
const char* kRowNames[kRows] = {"ground truth", "ground truth, keypoints", "input keypoints", "fit (w C + CG)",
                                "fit + refine (+ Opt)"};

struct PerSequence {
  std::array<SequenceMetrics, kRows> metrics;
  double joint_error_fit = 0, joint_error_refined = 0;  // m, mean over hands, frames, joints
  double keypoint_error_input = 0;                      // m, input vs true keypoints
  double seconds_fit = 0, seconds_refine = 0;
  int64_t frames = 0, shifted_frames = 0;
  RefineReport report;
};

double mean_distance(const at::Tensor& a, const at::Tensor& b) {
  return (a.to(at::kDouble) - b.to(at::kDouble)).norm(2, {-1}).mean().item<double>();
}

// The output sequence: the input's object and states with new hands; the object path made
// relative to the output folder.
void write_result(const Sequence& in, const std::string& in_path, const HandMotion& hands, const std::string& out_path) {
  Sequence s = in;
  s.hands = hands;
  s.hands.vertices = at::Tensor();  // posed again on reading, as for every sequence
  s.object = relative_object_path(resolve_object_path(in, in_path), out_path);
  fs::create_directories(fs::path(out_path).parent_path());
  write_sequence(s, out_path);
}

PerSequence process(const RefineCliOptions& o, const std::array<const HandModel*, 2>& models, ObjectCache& objects,
                    const std::string& file, std::uint64_t seed) {
  const Sequence s = read_sequence(file);
  const auto entry = sequence_object(objects, s, file);
  const ArticulatedObject& object = entry->object;
  const ObjectDistance& distance = *entry->distance;
  PerSequence r;
  r.frames = s.num_frames();
  const std::vector<int> ids = model_keypoints(*models[1]);

  // Ground truth, then the keypoints X the refinement starts from.
  HandMotion truth = s.hands;
  const PosedHands posed_truth = pose_hands(models, truth);
  truth.vertices = posed_truth.vertices;
  const at::Tensor X_true = hand_features(truth.vertices, ids, object, s.object_states);
  const at::Tensor X = o.keypoints == "exact" ? X_true
                                              : corrupt_hand_features(X_true, s.fps, o.corruption, seed, &r.shifted_frames);
  const at::Tensor H_true = hand_features_to_world(X_true, s.object_states).positions;
  const at::Tensor H = hand_features_to_world(X, s.object_states).positions;
  r.keypoint_error_input = mean_distance(H, H_true);

  auto t0 = std::chrono::steady_clock::now();
  ManoFitOptions fit_options = o.fit;
  fit_options.threads = 1;  // sequences run in parallel instead
  const HandMotion fit = fit_mano(models, H, fit_options);
  auto t1 = std::chrono::steady_clock::now();
  RefineOptions refine_options = o.refine;
  refine_options.threads = 1;
  const HeldFrames held = refine_options.w_hold > 0 ? held_frames(object, s.object_states) : HeldFrames{};
  const HandMotion refined = refine_hands(models, distance, s.object_states, X, fit, refine_options, &r.report, held);
  auto t2 = std::chrono::steady_clock::now();
  r.seconds_fit = std::chrono::duration<double>(t1 - t0).count();
  r.seconds_refine = std::chrono::duration<double>(t2 - t1).count();
  r.joint_error_fit = mean_distance(pose_hands(models, fit).joints, posed_truth.joints);
  r.joint_error_refined = mean_distance(pose_hands(models, refined).joints, posed_truth.joints);

  auto measure = [&](const at::Tensor& points) {
    SequenceData d;
    d.name = s.name;
    d.object_states = s.object_states;
    d.hand_vertices = points;
    return evaluate_sequence(object, distance, d);
  };
  r.metrics[kTruth] = measure(truth.vertices);
  r.metrics[kTruthKeypoints] = measure(H_true);
  r.metrics[kInputKeypoints] = measure(H);
  r.metrics[kFit] = measure(fit.vertices);
  r.metrics[kRefined] = measure(refined.vertices);

  if (!o.no_write) {
    const std::string name = fs::path(file).stem().string() + ".npz";
    write_result(s, file, fit, (fs::path(o.out) / "fit" / name).string());
    write_result(s, file, refined, (fs::path(o.out) / "refined" / name).string());
  }
  return r;
}

std::string cell(const MetricResult& m) {
  if (!std::isfinite(m.value)) return "-";
  if (m.frame_share) return fmt::format("{:.2f}", m.value);
  return fmt::format("{:.3f}", m.value);
}

int refine(RefineCliOptions o) {
  if (o.keypoints != "corrupted" && o.keypoints != "exact")
    throw Error("--keypoints must be 'corrupted' or 'exact', got '" + o.keypoints + "'");
  o.refine.validate();
  o.fit.validate();
  o.corruption.validate();
  std::vector<std::string> files = sequence_files(o.folder, o.split);
  // Outputs first: a folder that cannot be written fails now, not after the work.
  if (!o.no_write)
    for (const char* sub : {"fit", "refined"}) check_output_folder((fs::path(o.out) / sub).string());
  if (!o.json.empty()) check_output_file(o.json);
  if (o.limit > 0 && static_cast<size_t>(o.limit) < files.size()) files.resize(static_cast<size_t>(o.limit));
  const int threads = resolve_threads(o.threads);
  runtime::set_threads(1);  // one sequence per thread

  const std::string left = o.mano_left.empty() ? find_data_file("models/hand/mano_left.npz") : o.mano_left;
  const std::string right = o.mano_right.empty() ? find_data_file("models/hand/mano_right.npz") : o.mano_right;
  const std::array<HandModel, 2> hands = load_hand_models(left, right);
  const std::array<const HandModel*, 2> models{&hands[0], &hands[1]};

  ObjectCache objects;
  std::vector<PerSequence> results(files.size());
  const auto t0 = std::chrono::steady_clock::now();
  {
    ProgressBar bar("refining", files.size(), true);
    parallel_for(files.size(), threads, [&](size_t i) {
      try {
        results[i] = process(o, models, objects, files[i], o.seed * 1000003u + i);
      } catch (const Error& e) {
        throw in_sequence_file(files[i], e);
      }
      bar.step();
    });
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // The table: the paper's columns (without Mul and CM), then errors to the ground truth.
  std::array<std::vector<MetricResult>, kRows> table;
  for (int r = 0; r < kRows; ++r) {
    std::vector<SequenceMetrics> m;
    for (const PerSequence& p : results) m.push_back(p.metrics[static_cast<size_t>(r)]);
    table[static_cast<size_t>(r)] = aggregate_metrics(m, {});
  }
  double jf = 0, jr = 0, ki = 0, sf = 0, sr = 0;
  int64_t frames = 0, shifted = 0;
  for (const PerSequence& p : results) {
    jf += p.joint_error_fit;
    jr += p.joint_error_refined;
    ki += p.keypoint_error_input;
    sf += p.seconds_fit;
    sr += p.seconds_refine;
    frames += p.frames;
    shifted += p.shifted_frames;
  }
  const double n = static_cast<double>(results.size());
  std::cout << fmt::format("{:<28}{:>10}{:>10}{:>10}{:>10}{:>10}{:>10}{:>10}{:>14}\n", "", "Accel ↓", "Pen 1cm ↓",
                           "Pen 5mm ↓", "Pen 3mm ↓", "Depth ↓", "Con ↑", "Art ↑", "joint err mm");
  for (int r = 0; r < kRows; ++r) {
    const auto& t = table[static_cast<size_t>(r)];
    const auto col = [&](const char* name) {
      for (const auto& m : t)
        if (m.name == name) return cell(m);
      throw Error(std::string("refine table: no column ") + name);
    };
    std::string err = r == kFit ? fmt::format("{:.2f}", 1e3 * jf / n)
                                : (r == kRefined ? fmt::format("{:.2f}", 1e3 * jr / n) : std::string("-"));
    std::cout << fmt::format("{:<28}{:>10}{:>10}{:>10}{:>10}{:>10}{:>10}{:>10}{:>14}\n", kRowNames[r], col("Accel"),
                             col("Pen 1cm"), col("Pen 5mm"), col("Pen 3mm"), col("Depth"), col("Con"), col("Art"), err);
  }
  std::cout << fmt::format(
      "{} sequences, {} frames; keypoints: {} (mean error to the truth {:.2f} mm, {:.1f}% of hand-frames shifted "
      "into the object)\n",
      results.size(), frames, o.keypoints, 1e3 * ki / n, 100.0 * static_cast<double>(shifted) / (2.0 * static_cast<double>(frames)));
  std::cout << fmt::format(
      "time: fit {:.1f} s, refine {:.1f} s (one thread each, {:.2f} s per 64 frames for both), {:.1f} s wall on {} "
      "threads\n",
      sf, sr, (sf + sr) * 64.0 / static_cast<double>(frames), wall, threads);
  std::cout << "rows: 'keypoints' rows measure the 100 keypoints per hand as if they were the mesh; units: "
               "Accel cm/frame², Pen/Con/Art % of frames, Depth mm (mean over contact frames)\n";
  if (!o.no_write) std::cout << "wrote " << (fs::path(o.out) / "fit").string() << " and " << (fs::path(o.out) / "refined").string() << "\n";

  if (!o.json.empty()) {
    nlohmann::json j;
    j["sequences"] = results.size();
    j["frames"] = frames;
    j["keypoints"] = o.keypoints;
    for (int r = 0; r < kRows; ++r)
      for (const MetricResult& m : table[static_cast<size_t>(r)])
        if (std::isfinite(m.value)) j["rows"][kRowNames[r]][m.name] = m.value;
    j["joint_error_mm"] = {{"fit", 1e3 * jf / n}, {"refined", 1e3 * jr / n}};
    j["seconds"] = {{"fit", sf}, {"refine", sr}, {"wall", wall}, {"threads", threads}};
    write_file_atomically(o.json, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
    std::cout << "wrote " << o.json << "\n";
  }
  return 0;
}

}  // namespace

void add_refine_commands(CLI::App& app, Commands& out) {
  static RefineCliOptions o;
  CLI::App* cmd = app.add_subcommand(
      "refine", "fit MANO to keypoints and refine against the object, over a folder of sequences, with metrics");
  cmd->add_option("folder", o.folder, "a data set or a folder of sequences (*.npz)")->required();
  cmd->add_option("--split", o.split, "only the files listed under this key of <folder>/manifest.json (e.g. test)");
  cmd->add_option("--keypoints", o.keypoints,
                  "where the keypoints come from: 'corrupted' (the ground truth's, with a diffusion model's typical "
                  "errors) or 'exact'")
      ->capture_default_str();
  cmd->add_option("--out", o.out, "folder for the results: <out>/fit/*.npz and <out>/refined/*.npz")->capture_default_str();
  cmd->add_flag("--no-write", o.no_write, "do not write the sequences");
  cmd->add_option("--limit", o.limit, "only the first N sequences")->check(CLI::NonNegativeNumber);
  add_seed_option(cmd, o.seed, "corruption seed (default 1)");
  cmd->add_option("--json", o.json, "also write the table to this JSON file");
  cmd->add_option("--w-proj", o.refine.w_proj, "refinement: projection weight")->capture_default_str();
  cmd->add_option("--w-pen", o.refine.w_pen, "refinement: penetration weight (grows while too deep)")->capture_default_str();
  cmd->add_option("--w-acc", o.refine.w_acc, "refinement: acceleration weight")->capture_default_str();
  cmd->add_option("--w-fit", o.refine.w_fit, "refinement: keypoint weight")->capture_default_str();
  cmd->add_option("--w-hold", o.refine.w_hold, "refinement: hold weight (a hand on the object where it moves; 0 = off)")
      ->capture_default_str();
  cmd->add_option("--w-limits", o.refine.w_limits, "refinement: anatomical joint-limit weight (0 = off)")
      ->capture_default_str();
  cmd->add_option("--joint-angles", o.refine.joint_angles,
                  "refinement: finger joints as angles bounded by their ranges (false: axis-angles, the paper's)")
      ->capture_default_str();
  cmd->add_option("--backtrack", o.refine.backtrack,
                  "refinement: cut back a round's step in frames it took deeper into the object (false: the paper's)")
      ->capture_default_str();
  cmd->add_option("--w-pose", o.refine.w_pose, "refinement: finger pose held near the fit's (0 = off)")
      ->capture_default_str();
  cmd->add_option("--w-separation", o.refine.w_separation, "refinement: two fingers' bones kept apart (0 = off)")
      ->capture_default_str();
  cmd->add_option("--fit-w-separation", o.fit.w_separation, "MANO fit: two fingers' bones kept apart (0 = off)")
      ->capture_default_str();
  cmd->add_option("--fit-w-limits", o.fit.w_limits, "MANO fit: anatomical joint-limit weight (0 = off)")
      ->capture_default_str();
  cmd->add_option("--fit-w-fingers", o.fit.w_fingers, "MANO fit: fingers side by side across the hand (0 = off)")
      ->capture_default_str();
  cmd->add_option("--pen-exit-depth", o.refine.pen_exit_depth,
                  "refinement: frames deeper than this (m) push inside vertices out towards the rest of the hand (1e9 = off)")
      ->capture_default_str();
  cmd->add_option("--rounds", o.refine.outer_iterations, "refinement: surface linearisations")->capture_default_str();
  cmd->add_option("--max-rounds", o.refine.max_outer_iterations,
                  "refinement: rounds while a frame is deeper than 2 mm (the pipelines: 6)")
      ->capture_default_str();
  cmd->add_option("--max-pen-boost", o.refine.max_pen_boost,
                  "refinement: the largest that a frame's penetration weight grows to, x w_pen (default: no cap; the pipelines: 1000)");
  cmd->add_option("--pen-cavities", o.refine.pen_cavities,
                  "refinement: hand vertices in a hollow part's cavity behind a wall leave through it (the pipelines: true)")
      ->capture_default_str();
  cmd->add_option("--pen-fingers-through", o.refine.pen_fingers_through,
                  "refinement: a finger through a thin part comes back through it whole")
      ->capture_default_str();
  cmd->add_option("--steps", o.refine.max_iterations, "refinement: solver steps per round")->capture_default_str();
  cmd->add_option("--noise", o.corruption.noise, "corruption: RMS keypoint error (m)")->capture_default_str();
  cmd->add_option("--jitter", o.corruption.jitter, "corruption: RMS per-frame hand offset (m)")->capture_default_str();
  cmd->add_option("--mano-left", o.mano_left, "left hand model .npz (default: the shipped hand)");
  cmd->add_option("--mano-right", o.mano_right, "right hand model .npz (give both)");
  out.push_back({cmd, [] { return refine(o); }, false});
}

}  // namespace bimart::cli
