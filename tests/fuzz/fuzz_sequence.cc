// .npy / .npz and sequence files (core/io/npz.cc, sequence.cc): an input that starts like
// a .npy is parsed from memory, anything else is read as a sequence archive.
#include <cstring>

#include "core/io/npz.h"
#include "core/io/sequence.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size >= 6 && std::memcmp(data, "\x93NUMPY", 6) == 0) {
    bimart::fuzz::only_bimart_errors([&] {
      const bimart::NpyArray a = bimart::parse_npy(data, size, "fuzz.npy");
      if (a.is_numeric()) bimart::as_vector<double>(a, "fuzz.npy");
      else bimart::as_strings(a, "fuzz.npy");
    });
    return 0;
  }
  const std::string path = bimart::fuzz::input_file(data, size, ".npz");
  bimart::fuzz::only_bimart_errors([&] { bimart::read_sequence(path); });
  return 0;
}
