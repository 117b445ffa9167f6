// bimart data stats FOLDER [--variant np_bps|npa_bps|u_bps] [--out stats.npz]: the train
// split through the training data loader, a summary, and the normalisation file
// (docs/data_loader.md).
#include "core/cli/data_stats_command.h"
#include "core/metrics/hand_vertices.h"

#include <fmt/format.h>
#include <unistd.h>

#include <iostream>
#include <memory>
#include <string>

#include <ATen/ATen.h>

#include "core/data/normalization.h"
#include "core/data/window_dataset.h"
#include "core/util/error.h"
#include "core/util/progress.h"

namespace bimart::cli {
namespace {

struct StatsOptions {
  std::string folder;
  std::string variant = "np_bps";
  std::string out;
  std::string basis;
  std::string mano_left, mano_right;
  int stride = 16;
  bool no_cache = false;
};

std::string gigabytes(double bytes) { return fmt::format("{:.3f} GB", bytes / (1024.0 * 1024.0 * 1024.0)); }

int run_stats(const StatsOptions& o) {
  WindowDatasetOptions opt;
  opt.variant = parse_bps_variant(o.variant);
  opt.basis_file = o.basis;
  opt.stride = o.stride;
  opt.cache = !o.no_cache;
  const bool show = isatty(STDERR_FILENO) && progress_enabled();
  opt.progress = [show](std::size_t done, std::size_t total) {
    if (!show) return;
    const int width = 30, filled = static_cast<int>(width * done / total);
    std::cerr << fmt::format("\rfeatures [{}{}] {}/{}", std::string(filled, '#'), std::string(width - filled, ' '),
                             done, total)
              << (done == total ? "\n" : "") << std::flush;
  };
  if (!o.mano_left.empty() || !o.mano_right.empty()) set_posing_hand_models(o.mano_left, o.mano_right);
  const WindowDataset ds = WindowDataset::open(o.folder, "train", opt);
  const NormalizationStats stats = compute_normalization(ds);
  // Not inside FOLDER by default: `bimart eval FOLDER` reads every .npz below it as a sequence.
  const std::string out = o.out.empty() ? "stats_" + o.variant + ".npz" : o.out;
  save_normalization(stats, out);

  const auto& r = ds.load_report();
  const double per_frame = static_cast<double>(ds.memory_bytes()) / static_cast<double>(ds.num_frames());
  std::cout << fmt::format("train split of {} ({}, basis {})\n", o.folder, o.variant, ds.basis_file());
  std::cout << fmt::format("  sequences  {} ({} computed, {} from the cache) in {:.1f} s\n", ds.sequences().size(),
                           r.computed, r.cached, r.seconds);
  std::cout << fmt::format("  frames     {}\n", ds.num_frames());
  std::cout << fmt::format("  windows    {} of {} frames, stride {}\n", ds.size(), ds.window(), ds.stride());
  std::cout << fmt::format("  memory     {} ({:.1f} KB per frame, O/C/X as float16)\n",
                           gigabytes(static_cast<double>(ds.memory_bytes())), per_frame / 1024.0);
  std::cout << fmt::format("  statistics over {} (window, frame) pairs, std floor {}\n", stats.count, stats.std_floor);
  auto range = [](const at::Tensor& t) {
    return fmt::format("{:.3g} .. {:.3g}", t.min().item<double>(), t.max().item<double>());
  };
  std::cout << fmt::format("  std        X {}, [O|G] {}, C {}\n", range(stats.x_std), range(stats.obj_std),
                           range(stats.c_std));
  std::cout << "wrote " << out << "\n";
  return 0;
}

}  // namespace

void add_data_stats_command(CLI::App& data, Commands& out) {
  auto o = std::make_shared<StatsOptions>();
  CLI::App* stats = data.add_subcommand(
      "stats", "open a data set's train split (features, windows) and write its normalisation statistics");
  stats->add_option("folder", o->folder, "data set folder (with manifest.json)")
      ->required()
      ->check(CLI::ExistingDirectory);
  stats->add_option("--variant", o->variant, "object encoder: np_bps (default), npa_bps or u_bps")
      ->check(CLI::IsMember({"np_bps", "npa_bps", "u_bps"}));
  stats->add_option("--out", o->out,
                    "normalisation file to write (default: stats_<variant>.npz in the current folder)");
  stats->add_option("--basis", o->basis, "BPS basis file (default: the variant's shipped file under models/bps/)")
      ->check(CLI::ExistingFile);
  stats->add_option("--stride", o->stride, "frames between window starts (default 16)")->check(CLI::PositiveNumber);
  stats->add_option("--mano-left", o->mano_left, "left hand model .npz to pose the hands with (default: shipped)");
  stats->add_option("--mano-right", o->mano_right, "right hand model .npz (give both; e.g. converted MANO for ARCTIC)");
  stats->add_flag("--no-cache", o->no_cache, "neither read nor write the feature cache FOLDER/cache/<variant>/");
  out.push_back({stats, [o] { return run_stats(*o); }, false});
}

}  // namespace bimart::cli
