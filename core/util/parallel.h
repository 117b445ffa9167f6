// Runs independent jobs on plain threads: job(i) for i in [0, n) on `threads` threads
// (the calling thread is one of them). The first exception stops the handing out of new
// jobs and is rethrown after all threads have joined. For coarse jobs (a file, a sequence);
// libtorch's own parallel_for is for loops inside one.
#pragma once

#include <cstddef>
#include <functional>

namespace bimart {

// `threads` if positive, else the number of cores (at least 1).
int resolve_threads(int threads);

void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& job);

}  // namespace bimart
