// Writing a plug-in: derive from a stage kind in stages/, give the class a static spec()
// and a constructor taking `const bimart::Params&`, then put one line in its .cc file:
//
//   BIMART_REGISTER_STAGE(MyStage)
//
// and build the library with bimart_add_plugin(...) (see docs/plugins.md). The macro only
// records the class inside the library; the host registers it after checking the ABI.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/pipeline/plugin_abi.h"
#include "core/pipeline/registry.h"

namespace bimart {

// Passed by the host to a library's register function; collects its stages.
class PluginRegistrar {
 public:
  explicit PluginRegistrar(std::string library) : library_(std::move(library)) {}
  void add(StageSpec spec, StageFactory factory) {
    entries_.push_back({std::move(spec), std::move(factory), library_});
  }
  std::vector<StageEntry>& entries() { return entries_; }

 private:
  std::string library_;
  std::vector<StageEntry> entries_;
};

namespace plugin_detail {

using SpecFn = StageSpec (*)();

// Records a stage class in this library's local list (defined in plugin_entry.cc, which
// every plug-in library links statically), with the identity of the code that registered
// it; returns true.
bool add_local_stage(SpecFn spec, StageFactory factory, const BimartPluginInfo* identity);

template <class T>
bool register_local() {
  static const BimartPluginInfo identity = BIMART_THIS_BUILD_INFO;  // this plug-in's compiler
  return add_local_stage(
      &T::spec, [](const Params& p) -> std::unique_ptr<Stage> { return std::make_unique<T>(p); },
      &identity);
}

}  // namespace plugin_detail
}  // namespace bimart

#define BIMART_CONCAT_INNER(a, b) a##b
#define BIMART_CONCAT(a, b) BIMART_CONCAT_INNER(a, b)

#define BIMART_REGISTER_STAGE(Class)                                           \
  namespace {                                                                  \
  const bool BIMART_CONCAT(bimart_registered_, __LINE__) =                     \
      ::bimart::plugin_detail::register_local<Class>();                        \
  }
