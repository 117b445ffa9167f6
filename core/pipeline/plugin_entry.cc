// Linked statically into every plug-in library (target bimart::plugin_entry). Holds the
// library's local list of stage classes and exports the two C entry points the host calls.
// Built with hidden visibility so each library keeps its own list.
#include "core/pipeline/plugin.h"

namespace bimart::plugin_detail {
namespace {

struct LocalStage {
  SpecFn spec;
  StageFactory factory;
};

std::vector<LocalStage>& local_stages() {
  static std::vector<LocalStage> stages;
  return stages;
}

}  // namespace

bool add_local_stage(SpecFn spec, StageFactory factory) {
  local_stages().push_back({spec, std::move(factory)});
  return true;
}

}  // namespace bimart::plugin_detail

extern "C" {

__attribute__((visibility("default"))) const BimartPluginInfo* bimart_plugin_info() {
  static const BimartPluginInfo info = {
      sizeof(BimartPluginInfo), alignof(BimartPluginInfo), BIMART_PLUGIN_ABI_VERSION,
      BIMART_VERSION_STRING,    BIMART_COMPILER_ID,        BIMART_TORCH_VERSION,
      BIMART_CXX11_ABI};
  return &info;
}

__attribute__((visibility("default"))) void bimart_plugin_register(bimart::PluginRegistrar* r) {
  for (const auto& s : bimart::plugin_detail::local_stages()) r->add(s.spec(), s.factory);
}

}  // extern "C"
