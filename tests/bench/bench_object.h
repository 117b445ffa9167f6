// The benchmarks' object: two rounded boxes, spacing chosen so that it has about 4,000
// vertices (the issues' benchmark size).
#pragma once

#include "core/object/articulated_object.h"
#include "core/object/families/primitives.h"

namespace bimart::bench {

inline const ArticulatedObject& bench_object() {
  static const ArticulatedObject o = [] {
    ArticulatedObject a;
    a.name = "bench";
    for (double spacing = 0.02;; spacing *= 0.97) {
      a.bottom = shapes::rounded_box({-0.15, -0.25, -0.04}, {0.15, 0.0, 0.0}, 0.005, spacing);
      a.top = shapes::rounded_box({-0.15, 0.0, -0.01}, {0.15, 0.22, 0.0}, 0.003, spacing);
      if (a.top.num_vertices() + a.bottom.num_vertices() >= 4000) break;
    }
    return a;
  }();
  return o;
}

}  // namespace bimart::bench
