// Runs independent jobs on plain threads: job(i) for i in [0, n) on `threads` threads
// (the calling thread is one of them). The first exception stops the handing out of new
// jobs and is rethrown after all threads have joined. For coarse jobs (a file, a sequence);
// libtorch's own parallel_for is for loops inside one. With several workers each runs
// libtorch and OpenBLAS on one OpenMP thread, so the workers do not oversubscribe the cores.
#pragma once

#include <cstddef>
#include <functional>

namespace bimart {

// The most threads any work runs on: 4 x the cores (docs/cli.md). More only adds overhead,
// and a slip such as --threads 100000 would otherwise start that many.
int max_threads();
// `threads` if positive (at most max_threads()), else the default set below, else the
// number of cores (at least 1).
int resolve_threads(int threads);
// The default for resolve_threads(0): the global --threads of the CLI. 0: the cores.
void set_default_threads(int threads);

void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& job);

}  // namespace bimart
