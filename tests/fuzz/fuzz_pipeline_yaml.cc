// Pipeline YAML (core/pipeline/graph_file.cc): parse, duplicate keys, overrides.
#include <string>

#include "core/pipeline/graph.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  bimart::fuzz::only_bimart_errors([&] {
    bimart::GraphFile g = bimart::GraphFile::parse(text, "fuzz.yaml", "");
    g.apply_override("seed=3");
    if (!g.stages.empty()) g.apply_override(g.stages.front().id + ".frames=[1, 2]");
  });
  return 0;
}
