// The binary contract between the host and a plug-in library. A library exports two C
// functions; the host reads the info first and refuses the library, with a message, unless
// every field matches its own. Only then does it call the register function.
#pragma once

#include <cstdint>

#include "core/version.h"

#define BIMART_PLUGIN_ABI_VERSION 1u

namespace bimart {
class PluginRegistrar;
}

extern "C" {

struct BimartPluginInfo {
  std::uint32_t struct_size;   // sizeof(BimartPluginInfo) in the library
  std::uint32_t struct_align;  // alignof(BimartPluginInfo)
  std::uint32_t abi_version;   // BIMART_PLUGIN_ABI_VERSION
  const char* bimart_version;  // BIMART_VERSION_STRING
  const char* compiler;        // compiler id and version
  const char* torch_version;   // libtorch version the library was built against
  std::int32_t cxx11_abi;      // _GLIBCXX_USE_CXX11_ABI
};

typedef const BimartPluginInfo* (*BimartPluginInfoFn)();
typedef void (*BimartPluginRegisterFn)(bimart::PluginRegistrar*);

}  // extern "C"

#define BIMART_PLUGIN_INFO_SYMBOL "bimart_plugin_info"
#define BIMART_PLUGIN_REGISTER_SYMBOL "bimart_plugin_register"

// Compile-time identity of this build, compared field by field by the loader.
#if defined(__clang__)
#define BIMART_COMPILER_ID "clang " __clang_version__
#elif defined(__GNUC__)
#define BIMART_COMPILER_ID "gcc " __VERSION__
#else
#define BIMART_COMPILER_ID "unknown"
#endif
#ifdef _GLIBCXX_USE_CXX11_ABI
#define BIMART_CXX11_ABI _GLIBCXX_USE_CXX11_ABI
#else
#define BIMART_CXX11_ABI -1
#endif
