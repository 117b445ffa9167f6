// FNV-1a, 64 bit: fingerprints of the inputs that decide a cached result (feature caches,
// sweep jobs). Not cryptographic; stable across platforms and runs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace bimart {

struct Fnv {
  std::uint64_t h = 1469598103934665603ull;
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  }
  // With its terminating zero, so that ("ab", "c") and ("a", "bc") differ.
  void add(const std::string& s) { add(s.data(), s.size() + 1); }
  template <class T>
  void add_value(T v) {
    add(&v, sizeof v);
  }
  std::string hex() const;  // 16 hex digits
};

// The fingerprint of a file's bytes; throws bimart::Error naming the file if it cannot be read.
std::string file_fingerprint(const std::string& path);

}  // namespace bimart
