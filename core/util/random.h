// Portable seeded random numbers: std::mt19937_64 is fully specified by the standard, the
// distributions are ours (the standard library's differ between implementations), so the
// same seed gives the same numbers on every platform. Used wherever output must be
// reproducible byte for byte (data synthesis).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace bimart {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}

  // Uniform in [0, 1).
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  // Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Standard normal (Box-Muller).
  double normal() {
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2 * M_PI * u2);
  }
  // Uniform integer in [lo, hi] (inclusive).
  int integer(int lo, int hi) {
    return lo + static_cast<int>(uniform() * static_cast<double>(hi - lo + 1));
  }
  bool chance(double p) { return uniform() < p; }
  // A seed for an independent stream (e.g. one per sequence).
  std::uint64_t next_seed() { return engine_(); }

 private:
  std::mt19937_64 engine_;
};

}  // namespace bimart
