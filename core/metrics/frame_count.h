// A frame share's counts (Pen, Con, Art): frames that pass among frames considered.
// Summed over sequences before dividing (DESIGN §6).
#pragma once

#include <cstdint>

namespace bimart {

struct FrameCount {
  std::int64_t hits = 0;    // frames that pass the test
  std::int64_t frames = 0;  // frames considered
  FrameCount& operator+=(const FrameCount& o) {
    hits += o.hits;
    frames += o.frames;
    return *this;
  }
};

}  // namespace bimart
