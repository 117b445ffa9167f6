#include "core/diffusion/distributed.h"

#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#include <torch/csrc/distributed/c10d/TCPStore.hpp>

#include <ATen/ATen.h>

#include <cctype>
#include <chrono>
#include <cstdlib>

#include "core/util/error.h"

namespace bimart::diffusion {

struct DataParallel::Impl {
  c10::intrusive_ptr<::c10d::Store> store;
  c10::intrusive_ptr<::c10d::ProcessGroupGloo> group;
};

namespace {

const char* env(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? v : nullptr;
}

int parse_int(const char* name, const char* v, int lo, int hi) {
  char* end = nullptr;
  const long x = std::strtol(v, &end, 10);
  if (end == v || *end != '\0' || x < lo || x > hi)
    throw Error(std::string("distributed training: ") + name + "='" + v + "' is not a whole number in [" +
                std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<int>(x);
}

// The torch variable, else the Slurm one, else an error naming both.
int torch_or_slurm(const char* torch_name, const char* slurm_name, bool in_slurm, int lo, int hi) {
  if (const char* v = env(torch_name)) return parse_int(torch_name, v, lo, hi);
  if (in_slurm)
    if (const char* v = env(slurm_name)) return parse_int(slurm_name, v, lo, hi);
  throw Error(std::string("distributed training: ") + torch_name + " is not set" +
              (in_slurm ? std::string(" (nor ") + slurm_name + ")" : std::string()));
}

// A Gloo device that reaches the other processes: loopback for a master on this machine,
// else the interface GLOO_SOCKET_IFNAME names, else the address this host's name resolves to.
std::shared_ptr<::gloo::transport::Device> gloo_device(const std::string& master_addr) {
  if (master_addr == "127.0.0.1" || master_addr == "localhost")
    return ::c10d::ProcessGroupGloo::createDeviceForHostname(master_addr);
  if (const char* ifname = env("GLOO_SOCKET_IFNAME")) return ::c10d::ProcessGroupGloo::createDeviceForInterface(ifname);
  return ::c10d::ProcessGroupGloo::createDefaultDevice();
}

void wait(const c10::intrusive_ptr<::c10d::Work>& work, const char* what) {
  try {
    work->wait();
  } catch (const std::exception& e) {
    throw Error(std::string("distributed training: ") + what + " failed: " + e.what());
  }
}

}  // namespace

DataParallel::DataParallel(const DataParallelOptions& o) : options_(o), impl_(std::make_unique<Impl>()) {
  if (o.world_size < 1 || o.rank < 0 || o.rank >= o.world_size)
    throw Error("distributed training: rank " + std::to_string(o.rank) + " is outside a world of " +
                std::to_string(o.world_size));
  const auto timeout = std::chrono::milliseconds(static_cast<long>(o.timeout_seconds * 1000));
  try {
    ::c10d::TCPStoreOptions so;
    so.port = static_cast<std::uint16_t>(o.master_port);
    so.isServer = o.rank == 0;
    so.numWorkers = o.world_size;
    so.waitWorkers = true;
    so.timeout = timeout;
    impl_->store = c10::make_intrusive<::c10d::TCPStore>(o.master_addr, so);
    auto go = c10::make_intrusive<::c10d::ProcessGroupGloo::Options>(timeout);
    go->devices.push_back(gloo_device(o.master_addr));
    impl_->group = c10::make_intrusive<::c10d::ProcessGroupGloo>(impl_->store, o.rank, o.world_size, go);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error("distributed training: cannot join the group at " + o.master_addr + ":" +
                std::to_string(o.master_port) + " as rank " + std::to_string(o.rank) + " of " +
                std::to_string(o.world_size) + ": " + e.what());
  }
}

DataParallel::~DataParallel() = default;

std::string first_slurm_host(const std::string& nodelist) {
  // The first entry (commas inside brackets separate numbers, not hosts), then each
  // bracket group replaced by its first number: "r[2-3]n[01-04]" -> "r2n01".
  std::string first;
  int depth = 0;
  for (const char c : nodelist) {
    if (c == ',' && depth == 0) break;
    depth += c == '[' ? 1 : c == ']' ? -1 : 0;
    first += c;
  }
  std::string host;
  for (std::size_t i = 0; i < first.size(); ++i) {
    if (first[i] != '[') {
      host += first[i];
      continue;
    }
    const std::size_t close = first.find(']', i);
    std::size_t n = i + 1;
    while (n < first.size() && std::isdigit(static_cast<unsigned char>(first[n]))) ++n;
    if (close == std::string::npos || n == i + 1)
      throw Error("distributed training: cannot read the Slurm node list '" + nodelist + "'");
    host += first.substr(i + 1, n - i - 1);
    i = close;
  }
  if (host.empty()) throw Error("distributed training: the Slurm node list is empty");
  return host;
}

std::optional<DataParallelOptions> DataParallel::options_from_environment() {
  // Inside an srun step of several tasks; a batch script (no step) is one process.
  const char* step_tasks = env("SLURM_STEP_NUM_TASKS");
  const bool in_slurm = step_tasks != nullptr && parse_int("SLURM_STEP_NUM_TASKS", step_tasks, 1, 65536) > 1;
  if (env("WORLD_SIZE") == nullptr && !in_slurm) return std::nullopt;
  DataParallelOptions o;
  o.world_size = torch_or_slurm("WORLD_SIZE", "SLURM_STEP_NUM_TASKS", in_slurm, 1, 65536);
  if (o.world_size == 1) return std::nullopt;
  o.rank = torch_or_slurm("RANK", "SLURM_PROCID", in_slurm, 0, o.world_size - 1);
  const char* nodes = env("SLURM_STEP_NODELIST") ? env("SLURM_STEP_NODELIST") : env("SLURM_JOB_NODELIST");
  if (const char* addr = env("MASTER_ADDR"))
    o.master_addr = addr;
  else if (in_slurm && nodes != nullptr)
    o.master_addr = first_slurm_host(nodes);
  else
    throw Error(std::string("distributed training: MASTER_ADDR is not set") + (in_slurm ? " (nor SLURM_STEP_NODELIST)" : ""));
  const char* job = env("SLURM_JOB_ID");
  if (const char* port = env("MASTER_PORT"))
    o.master_port = parse_int("MASTER_PORT", port, 1, 65535);
  else if (in_slurm && job != nullptr)  // one port per job, so two jobs' ranks on a node do not meet
    o.master_port = 15000 + parse_int("SLURM_JOB_ID", job, 0, 2147483647) % 20000;
  else
    throw Error(std::string("distributed training: MASTER_PORT is not set") + (in_slurm ? " (nor SLURM_JOB_ID)" : ""));
  return o;
}

std::shared_ptr<DataParallel> DataParallel::from_environment() {
  const auto o = options_from_environment();
  return o ? std::make_shared<DataParallel>(*o) : nullptr;
}

namespace {

// One contiguous buffer of the tensors' values (same dtype), and the copy back.
at::Tensor flatten(const std::vector<at::Tensor>& tensors) {
  std::vector<at::Tensor> flat;
  flat.reserve(tensors.size());
  for (const auto& t : tensors) flat.push_back(t.detach().reshape({-1}));
  return at::cat(flat);
}
void unflatten(const at::Tensor& buffer, const std::vector<at::Tensor>& tensors) {
  std::int64_t offset = 0;
  for (const auto& t : tensors) {
    const auto n = t.numel();
    t.detach().copy_(buffer.slice(0, offset, offset + n).view(t.sizes()));
    offset += n;
  }
}

}  // namespace

void DataParallel::all_reduce_sum(const std::vector<at::Tensor>& tensors) {
  if (tensors.empty()) return;
  std::vector<at::Tensor> buffer{flatten(tensors)};
  ::c10d::AllreduceOptions ao;
  ao.reduceOp = ::c10d::ReduceOp::SUM;
  wait(impl_->group->allreduce(buffer, ao), "all-reduce");
  unflatten(buffer[0], tensors);
}

double DataParallel::all_reduce_sum(double value) {
  const at::Tensor t = at::full({1}, value, at::kDouble);
  all_reduce_sum(std::vector<at::Tensor>{t});
  return t.item<double>();
}

void DataParallel::broadcast(const std::vector<at::Tensor>& tensors) {
  if (tensors.empty()) return;
  std::vector<at::Tensor> buffer{flatten(tensors)};
  ::c10d::BroadcastOptions bo;
  bo.rootRank = 0;
  wait(impl_->group->broadcast(buffer, bo), "broadcast");
  unflatten(buffer[0], tensors);
}

void DataParallel::barrier() { wait(impl_->group->barrier(), "barrier"); }

}  // namespace bimart::diffusion
