// glibc allocator settings for libtorch work. Every forward and backward allocates and frees
// tens of MB of temporaries; by default glibc maps large blocks afresh and gives freed memory
// back to the system, so every call pays the page faults again. Raising the mmap and trim
// thresholds keeps that memory in the process (LBS forward + backward: 26-31 ms -> 18-20 ms,
// docs/performance.md). Call once at start-up; a user's MALLOC_*_ environment settings win.
#pragma once

namespace bimart::runtime {

void tune_allocator();

}  // namespace bimart::runtime
