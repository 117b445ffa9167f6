// Data-parallel training over several processes or machines on libtorch's own distributed
// engine: c10d with the Gloo backend and a TCP store (docs/training.md, "Several
// machines"). Configured the torch way: MASTER_ADDR, MASTER_PORT, WORLD_SIZE, RANK.
#pragma once

#include <memory>
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

class DataParallel {
 public:
  // Joins the group (rank 0 hosts the store); blocks until all world_size processes joined
  // or the timeout passes (bimart::Error then).
  explicit DataParallel(const DataParallelOptions& options);
  ~DataParallel();
  DataParallel(const DataParallel&) = delete;
  DataParallel& operator=(const DataParallel&) = delete;

  // From MASTER_ADDR, MASTER_PORT, WORLD_SIZE and RANK; null when WORLD_SIZE is unset or 1.
  // Throws bimart::Error naming the variable for a malformed or missing value.
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
