// Linked statically into every plug-in library (target bimart::plugin_entry). Holds the
// library's local list of stage classes and exports the two C entry points the host calls.
// Built with hidden visibility so each library keeps its own list.
#include "core/pipeline/plugin.h"

namespace bimart::plugin_detail {
namespace {

struct LocalStage {
  SpecFn spec;
  StageFactory factory;
  const BimartPluginInfo* identity;
};

std::vector<LocalStage>& local_stages() {
  static std::vector<LocalStage> stages;
  return stages;
}

}  // namespace

bool add_local_stage(SpecFn spec, StageFactory factory, const BimartPluginInfo* identity) {
  local_stages().push_back({spec, std::move(factory), identity});
  return true;
}

}  // namespace bimart::plugin_detail

extern "C" {

// The identity recorded by the library's first registration (its own sources); a library
// without stages reports this file's.
__attribute__((visibility("default"))) const BimartPluginInfo* bimart_plugin_info() {
  static const BimartPluginInfo own = BIMART_THIS_BUILD_INFO;
  const auto& stages = bimart::plugin_detail::local_stages();
  return stages.empty() ? &own : stages.front().identity;
}

__attribute__((visibility("default"))) void bimart_plugin_register(bimart::PluginRegistrar* r) {
  for (const auto& s : bimart::plugin_detail::local_stages()) r->add(s.spec(), s.factory);
}

}  // extern "C"
