#include "core/diffusion/distributed.h"

#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#include <torch/csrc/distributed/c10d/TCPStore.hpp>

#include <ATen/ATen.h>

#include <chrono>
#include <cstdlib>

#include "core/util/error.h"

namespace bimart::diffusion {

struct DataParallel::Impl {
  c10::intrusive_ptr<::c10d::Store> store;
  c10::intrusive_ptr<::c10d::ProcessGroupGloo> group;
};

namespace {

int env_int(const char* name, int fallback, bool required, int lo, int hi) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') {
    if (required) throw Error(std::string("distributed training: ") + name + " is not set");
    return fallback;
  }
  char* end = nullptr;
  const long x = std::strtol(v, &end, 10);
  if (end == v || *end != '\0' || x < lo || x > hi)
    throw Error(std::string("distributed training: ") + name + "='" + v + "' is not a whole number in [" +
                std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<int>(x);
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
    go->devices.push_back(::c10d::ProcessGroupGloo::createDeviceForHostname(o.master_addr));
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

std::shared_ptr<DataParallel> DataParallel::from_environment() {
  const int world = env_int("WORLD_SIZE", 1, false, 1, 65536);
  if (world == 1) return nullptr;
  DataParallelOptions o;
  o.world_size = world;
  o.rank = env_int("RANK", 0, true, 0, world - 1);
  const char* addr = std::getenv("MASTER_ADDR");
  if (addr == nullptr || *addr == '\0') throw Error("distributed training: MASTER_ADDR is not set");
  o.master_addr = addr;
  o.master_port = env_int("MASTER_PORT", 29500, true, 1, 65535);
  return std::make_shared<DataParallel>(o);
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
