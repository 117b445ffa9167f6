#include "core/util/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include <ATen/Parallel.h>

// libgomp's ICV calls, declared here rather than through <omp.h>, which clang (the fuzz
// build) lacks; the library is libtorch's own OpenMP runtime (core/CMakeLists.txt).
extern "C" {
int omp_get_max_threads(void);
void omp_set_num_threads(int);
}

namespace bimart {

namespace {
std::atomic<int> default_threads{0};
int cores() { return std::max(1, static_cast<int>(std::thread::hardware_concurrency())); }
}  // namespace

int max_threads() { return 4 * cores(); }

int resolve_threads(int threads) {
  if (threads <= 0) threads = default_threads;
  if (threads <= 0) return cores();
  return std::min(threads, max_threads());
}

void set_default_threads(int threads) { default_threads = std::max(0, std::min(threads, max_threads())); }

void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& job) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  // With several workers, each runs libtorch and OpenBLAS on one OpenMP thread (the setting
  // is per thread): the workers already take the cores, and OpenMP teams of their own would
  // oversubscribe them (measured: the 2-thread MANO fit 1.27 s with, 0.79 s without).
  const bool single = threads > 1 && n > 1;
  auto worker = [&] {
    if (single) {
      at::get_num_threads();  // libtorch's per-thread set-up first, or it would undo the next line
      omp_set_num_threads(1);
    }
    for (std::size_t i; (i = next++) < n;) {
      try {
        job(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads && static_cast<std::size_t>(t) < n; ++t) pool.emplace_back(worker);
  at::get_num_threads();
  const int caller_threads = omp_get_max_threads();
  worker();
  if (single) omp_set_num_threads(caller_threads);
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace bimart
