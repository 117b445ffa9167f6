#include "core/util/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

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
  auto worker = [&] {
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
  worker();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace bimart
