// bimart train contact|motion CONFIG.yaml: trains a diffusion model (core/diffusion/
// training.h, docs/training.md). Ctrl-C or SIGTERM writes a checkpoint and stops (exit
// 130); --resume continues the identical run. Several processes train data-parallel when
// WORLD_SIZE > 1 (MASTER_ADDR, MASTER_PORT, RANK) or with the equivalent flags.
#include <csignal>

#include <atomic>
#include <cstdlib>
#include <iostream>

#include "core/cli/command.h"
#include "core/diffusion/distributed.h"
#include "core/diffusion/training.h"
#include "core/util/error.h"
#include "core/util/log.h"

namespace bimart::cli {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) { g_stop.store(true); }

struct TrainArgs {
  std::string model, config;
  bool resume = false;
  long long steps = 0;
  int world_size = 0, rank = -1, master_port = 0;
  std::string master_addr;
};

int run_train(const TrainArgs& a) {
  diffusion::TrainConfig config = diffusion::load_train_config(a.config);
  if (config.model != a.model)
    throw Error(a.config + ": this config trains the " + config.model + " model, not the " + a.model +
                " model (bimart train " + config.model + " " + a.config + ")");
  if (a.steps > 0) config.steps = a.steps;

  diffusion::TrainOptions options;
  options.resume = a.resume;
  options.stop_requested = [] { return g_stop.load(); };
  if (a.world_size > 1) {
    diffusion::DataParallelOptions d;
    d.world_size = a.world_size;
    d.rank = a.rank;
    if (d.rank < 0) throw Error("--world-size needs --rank");
    d.master_addr = a.master_addr.empty() ? "127.0.0.1" : a.master_addr;
    if (a.master_port > 0) d.master_port = a.master_port;
    options.parallel = std::make_shared<diffusion::DataParallel>(d);
  } else {
    options.parallel = diffusion::DataParallel::from_environment();
  }
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  const diffusion::TrainResult r = diffusion::train(config, options);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  if (!options.parallel || options.parallel->rank() == 0) {
    std::cout << "steps " << r.steps_done << "/" << config.steps << ", last loss " << r.last_loss
              << ", validation " << r.last_validation << ", " << r.windows_per_second << " windows/s\n";
    std::cout << "wrote " << r.checkpoint << "\n";
    if (!config.export_path.empty()) std::cout << "wrote " << config.export_path << "\n";
  }
  if (r.interrupted) {
    log::warn("interrupted at step {}: resume with bimart train {} {} --resume", r.steps_done, a.model, a.config);
    return 130;
  }
  return 0;
}

}  // namespace

void add_train_commands(CLI::App& app, Commands& out) {
  static TrainArgs a;
  CLI::App* cmd = app.add_subcommand("train", "train the contact or the motion diffusion model (docs/training.md)");
  cmd->add_option("model", a.model, "contact or motion")->required()->check(CLI::IsMember({"contact", "motion"}));
  cmd->add_option("config", a.config, "training config YAML (e.g. models/motion.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_flag("--resume", a.resume, "continue the run from its checkpoint (out/checkpoint.npz)");
  cmd->add_option("--steps", a.steps, "total steps (replaces training.steps)")->check(CLI::PositiveNumber);
  cmd->add_option("--world-size", a.world_size, "processes in all (default: WORLD_SIZE, else 1)")
      ->check(CLI::Range(1, 65536));
  cmd->add_option("--rank", a.rank, "this process's rank (default: RANK)")->check(CLI::Range(0, 65535));
  cmd->add_option("--master-addr", a.master_addr, "address of rank 0 (default: MASTER_ADDR)");
  cmd->add_option("--master-port", a.master_port, "port of rank 0 (default: MASTER_PORT)")->check(CLI::Range(1, 65535));
  out.push_back({cmd, [] { return run_train(a); }, false});
}

}  // namespace bimart::cli
