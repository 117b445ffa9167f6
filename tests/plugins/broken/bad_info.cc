// A library that exports the entry points but reports one wrong field in its info.
#include "core/pipeline/plugin_abi.h"

extern "C" {

__attribute__((visibility("default"))) const BimartPluginInfo* bimart_plugin_info() {
  static const BimartPluginInfo info = {
#ifdef BAD_FIELD_size
      sizeof(BimartPluginInfo) + 8,
#else
      sizeof(BimartPluginInfo),
#endif
      alignof(BimartPluginInfo),
#ifdef BAD_FIELD_abi
      999u,  // a version no bimart has
#else
      BIMART_PLUGIN_ABI_VERSION,
#endif
      BIMART_VERSION_STRING,
#ifdef BAD_FIELD_compiler
      "gcc 2.95",
#else
      BIMART_COMPILER_ID,
#endif
#ifdef BAD_FIELD_torch
      "0.4.1",
#else
      BIMART_TORCH_VERSION,
#endif
      BIMART_CXX11_ABI};
  return &info;
}

// Must never be called: the host refuses the library before.
__attribute__((visibility("default"))) void bimart_plugin_register(bimart::PluginRegistrar*) {
  __builtin_trap();
}
}
