// Shared by the libFuzzer harnesses (tests/fuzz/*.cc): the input as a file with a given
// extension (the loaders read files), and the one rule every harness checks: a loader may
// refuse its input only with a bimart::Error. Anything else — another exception, a
// sanitizer report, a crash, a hang — is a finding.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/util/error.h"

namespace bimart::fuzz {

// A scratch file of this process, rewritten for each input.
inline std::string input_file(const uint8_t* data, size_t size, const std::string& extension) {
  static const std::string dir = [] {
    const std::string d = (std::filesystem::temp_directory_path() / ("bimart_fuzz_" + std::to_string(::getpid()))).string();
    std::filesystem::create_directories(d);
    return d;
  }();
  const std::string path = dir + "/input" + extension;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data),
                                                                static_cast<std::streamsize>(size));
  return path;
}

template <class F>
void only_bimart_errors(F&& load) {
  try {
    load();
  } catch (const Error&) {
    // A clear refusal: what bad input must get.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "finding: a loader threw %s instead of bimart::Error\n", e.what());
    std::abort();
  }
}

}  // namespace bimart::fuzz
