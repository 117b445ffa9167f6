// BPS basis files (core/features/bps.cc, load_bps_basis).
#include "core/features/bps.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = bimart::fuzz::input_file(data, size, ".npz");
  bimart::fuzz::only_bimart_errors([&] { bimart::load_bps_basis(path); });
  return 0;
}
