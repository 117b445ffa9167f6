#include "core/runtime/allocator.h"

#include <malloc.h>

#include <cstdlib>

namespace bimart::runtime {

void tune_allocator() {
  constexpr int kThreshold = 256 << 20;  // 256 MB
  if (std::getenv("MALLOC_MMAP_THRESHOLD_") == nullptr) mallopt(M_MMAP_THRESHOLD, kThreshold);
  if (std::getenv("MALLOC_TRIM_THRESHOLD_") == nullptr) mallopt(M_TRIM_THRESHOLD, kThreshold);
}

}  // namespace bimart::runtime
