// Data-parallel training over several processes or machines on libtorch's own distributed
// engine: c10d with the Gloo backend and a TCP store (docs/training.md, "Several
// machines"). Configured the torch way: MASTER_ADDR, MASTER_PORT, WORLD_SIZE, RANK; inside
// a Slurm step (srun) Slurm's variables stand in for those that are unset (docs/cluster.md).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <ATen/core/Tensor.h>

namespace bimart::diffusion {

struct DataParallelOptions {
  std::string master_addr = "127.0.0.1";
  int master_port = 29500;
  int world_size = 1;
  int rank = 0;
  double timeout_seconds = 300;  // for joining and for each collective
};

// The first host of a Slurm node list: "gpu[03-05,9],cpu1" -> "gpu03". Throws
// bimart::Error for an empty or malformed list.
std::string first_slurm_host(const std::string& nodelist);

class DataParallel {
 public:
  // Joins the group (rank 0 hosts the store); blocks until all world_size processes joined
  // or the timeout passes (bimart::Error then).
  explicit DataParallel(const DataParallelOptions& options);
  ~DataParallel();
  DataParallel(const DataParallel&) = delete;
  DataParallel& operator=(const DataParallel&) = delete;

  // The group this process belongs to, from MASTER_ADDR, MASTER_PORT, WORLD_SIZE and RANK.
  // Inside a Slurm step of several tasks (SLURM_STEP_NUM_TASKS > 1) an unset one comes from
  // Slurm: the world from SLURM_STEP_NUM_TASKS, the rank from SLURM_PROCID, the master
  // from the first host of SLURM_STEP_NODELIST (or SLURM_JOB_NODELIST), the port
  // 15000 + SLURM_JOB_ID mod 20000. Empty for one process. Throws bimart::Error naming the
  // variable for a malformed or missing value.
  static std::optional<DataParallelOptions> options_from_environment();
  // Joins the group options_from_environment() names; null for one process.
  static std::shared_ptr<DataParallel> from_environment();

  int rank() const { return options_.rank; }
  int world_size() const { return options_.world_size; }

  // In place, element-wise sums over all processes: each tensor in turn is flattened into
  // one buffer (Gloo reduces one buffer per call), reduced and copied back.
  void all_reduce_sum(const std::vector<at::Tensor>& tensors);
  double all_reduce_sum(double value);
  // In place: every process receives rank 0's values.
  void broadcast(const std::vector<at::Tensor>& tensors);
  void barrier();

 private:
  struct Impl;
  DataParallelOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bimart::diffusion
